"""MotionGenerator.generate's env_guidance_fallback: physically impossible samples re-sampled at a milder s_e."""

from __future__ import annotations

import pytest
import torch

from simdiff.errors import SimdiffError
from simdiff.model import ModelConfig, MotionGenerator, SimConfig, backbone_preset, build_network
from simdiff.model.generator import impossible
from simdiff.train.testing import HashTextEncoder
from simdiff.motion.features import joints_to_features
from simdiff.motion.synthetic import walk


def _tiny(mean: torch.Tensor | None = None, std: float = 1.0) -> MotionGenerator:
    torch.manual_seed(0)
    config = ModelConfig(backbone=backbone_preset("tiny"), sim=SimConfig())
    return MotionGenerator(build_network(config), config, HashTextEncoder(), mean=torch.zeros(263) if mean is None else mean,
                           std=torch.full((263,), std))


def test_impossible_flags_floating_and_gliding_clips_only() -> None:
    gait = torch.from_numpy(joints_to_features(walk(40, speed=1.4)))
    floating = gait.clone()
    floating[:, 3] += 1.0
    floating[:, 5:67:3] += 1.0
    statue = torch.zeros_like(gait)
    statue[:, 1] = 0.1  # 2 m/s forward, no joint moving: a glide
    statue[:, 3] = 0.9
    statue[:, 4:67] = torch.tensor([0.0, 0.05, 0.0] * 21)
    batch = torch.stack([gait, floating, statue, statue])
    n = len(gait)
    assert impossible(batch, torch.tensor([n, n, n, 1])).tolist() == [False, True, True, False]  # 1 frame: never


def test_fallback_replaces_only_the_impossible_rows_with_the_fallback_sample() -> None:
    mean = torch.zeros(263)
    mean[3] = 1.5  # every raw sample a metre up: all impossible
    mean[5:67:3] = 1.2
    gen = _tiny(mean, std=0.01)
    kw = dict(env=(-1.6, 0.0, 0.0), steps=2, seed=3)
    plain4 = gen.generate(["a person runs"] * 2, 12, env_guidance=4.0, **kw)
    plain2 = gen.generate(["a person runs"] * 2, 12, env_guidance=2.0, **kw)
    assert plain4.fell_back is None and not torch.equal(plain4.features, plain2.features)
    out = gen.generate(["a person runs"] * 2, 12, env_guidance=4.0, env_guidance_fallback=2.0, **kw)
    assert out.fell_back.tolist() == [True, True]
    assert torch.equal(out.features, plain2.features)  # the same seed: each row is the fallback's own sample
    same = gen.generate(["a person runs"] * 2, 12, env_guidance=4.0, env_guidance_fallback=4.0, **kw)
    assert torch.equal(same.features, plain4.features) and same.fell_back.tolist() == [False, False]


def test_a_possible_sample_keeps_its_s_e() -> None:
    standing = torch.from_numpy(joints_to_features(walk(12, speed=1.4))).mean(dim=0)
    standing[1:3] = 0.0  # no root travel: a pose standing on the floor, which any body can hold
    gen = _tiny(standing, std=1e-4)
    kw = dict(env=(-1.6, 0.0, 0.0), steps=2, seed=3)
    out = gen.generate(["a person stands"], 12, env_guidance=4.0, env_guidance_fallback=2.0, **kw)
    assert out.fell_back.tolist() == [False]
    assert torch.equal(out.features, gen.generate(["a person stands"], 12, env_guidance=4.0, **kw).features)


def test_bad_fallback_is_one_line() -> None:
    gen = _tiny()
    with pytest.raises(SimdiffError, match="env guidance fallback must be a finite number ≥ 0, got -1.0"):
        gen.generate(["walk"], 8, env_guidance=2.0, env_guidance_fallback=-1.0, steps=1)
    assert torch.isfinite(gen.generate(["walk"], 8, env_guidance=2.0, env_guidance_fallback=1.0, steps=1).features).all()
