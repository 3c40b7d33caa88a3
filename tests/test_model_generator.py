"""Weights I/O (model.safetensors + config.json) and the inference-only MotionGenerator."""

from __future__ import annotations

import json

import pytest
import torch

from simdiff.errors import SimdiffError
from simdiff.model import ModelConfig, MotionGenerator, SimConfig, backbone_preset, build_network, load_pretrained


class HashText:
    name = "minilm"
    dim = 384

    def encode(self, texts: list[str]) -> torch.Tensor:
        return torch.stack([torch.randn(384, generator=torch.Generator().manual_seed(len(t) * 7919 + ord(t[0]))) for t in texts])


def tiny(sim: bool = False) -> ModelConfig:
    return ModelConfig(backbone=backbone_preset("tiny"), sim=SimConfig() if sim else None)


def test_save_load_round_trip(tmp_path) -> None:
    config = tiny(sim=True)
    gen = MotionGenerator(build_network(config), config, HashText(), torch.full((263,), 2.0), torch.full((263,), 3.0))
    gen.save(tmp_path)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["config.json", "model.safetensors"]
    assert json.loads((tmp_path / "config.json").read_text())["sim"]["mode"] == "continuous"
    net, cfg, extra = load_pretrained(tmp_path)
    assert cfg == config
    for key, value in gen.network.state_dict().items():
        assert torch.equal(net.state_dict()[key], value)
    assert torch.equal(extra["normalizer.std"], torch.full((263,), 3.0))


def test_generate_shapes_lengths_and_seed(tmp_path) -> None:
    config = tiny()
    gen = MotionGenerator(build_network(config), config, HashText(), torch.full((263,), 1.0), torch.full((263,), 2.0))
    out = gen.generate(["a person walks", "a person jumps"], [30, 20], sampler="ddim", steps=5, seed=3)
    assert out.features.shape == (2, 30, 263)
    assert torch.all(out.features[1, 20:] == 0)
    assert torch.allclose(out.features[0], out.normalized[0] * 2 + 1)
    again = gen.generate(["a person walks", "a person jumps"], [30, 20], sampler="ddim", steps=5, seed=3)
    assert torch.equal(out.features, again.features)
    assert [c.shape[0] for c in out.clips()] == [30, 20]


def test_generate_rejects_bad_input() -> None:
    gen = MotionGenerator(build_network(tiny()), tiny(), HashText())
    with pytest.raises(SimdiffError, match="196"):
        gen.generate(["walk"], 197, steps=2)
    with pytest.raises(SimdiffError, match="backbone-only"):
        gen.generate(["walk"], 20, env=(-9.81, 0, 0), steps=2)
    sim = MotionGenerator(build_network(tiny(True)), tiny(True), HashText())
    with pytest.raises(SimdiffError, match="env must be"):
        sim.generate(["walk"] * 2, 20, env=[1.0, 2.0], steps=2)
    assert sim.generate(["walk"] * 2, 20, env=(-3.0, 5.0, 0.0), alpha=0.5, steps=2).features.shape == (2, 20, 263)


def test_backbone_anchor_gives_the_backbone_at_earth_and_is_validated() -> None:
    gen = reacting_generator()
    envs = [[-9.81, 0.0, 0.0], [-1.6, 0.0, 0.0]]
    anchored = gen.generate(["walk", "jump"], 12, env=envs, alpha=0.5, steps=3, seed=1, env_guidance=2.0,
                            anchor="backbone").features
    alone = gen.generate(["walk", "jump"], 12, env=envs, alpha=0.0, steps=3, seed=1).features
    assert torch.equal(anchored[0], alone[0]) and not torch.allclose(anchored[1], alone[1], atol=1e-4)
    with pytest.raises(SimdiffError, match="unknown guidance anchor 'none'"):
        gen.generate(["walk"], 12, env=envs[1], steps=2, anchor="none")
    backbone = MotionGenerator(build_network(tiny()), tiny(), HashText())
    with pytest.raises(SimdiffError, match="continuous Sim Encoder"):
        backbone.generate(["walk"], 12, steps=2, anchor="backbone")


def test_anchor_alpha_gives_alpha_a_at_earth_and_is_validated() -> None:
    gen = reacting_generator()
    envs = [[-9.81, 0.0, 0.0], [-1.6, 0.0, 0.0]]
    anchored = gen.generate(["walk", "jump"], 12, env=envs, alpha=0.5, steps=3, seed=1, env_guidance=2.0,
                            anchor="backbone", anchor_alpha=0.25).features
    quarter = gen.generate(["walk", "jump"], 12, env=envs, alpha=0.25, steps=3, seed=1).features
    backbone = gen.generate(["walk", "jump"], 12, env=envs, alpha=0.5, steps=3, seed=1, env_guidance=2.0,
                            anchor="backbone").features
    assert torch.equal(anchored[0], quarter[0]) and not torch.allclose(anchored[0], backbone[0], atol=1e-4)
    with pytest.raises(SimdiffError, match="anchor alpha 0.25 needs the backbone, reference or edit anchor"):
        gen.generate(["walk"], 12, env=envs[1], steps=2, anchor_alpha=0.25)
    with pytest.raises(SimdiffError, match="anchor alpha must be a finite number"):
        gen.generate(["walk"], 12, env=envs[1], steps=2, anchor="backbone", anchor_alpha=-1.0)


def test_anchor_t_max_switches_the_anchor_at_the_late_steps_and_is_validated() -> None:
    gen = reacting_generator()
    envs = [[-9.81, 0.0, 0.0], [-1.6, 0.0, 0.0]]
    kw = dict(env=envs, alpha=0.5, steps=4, seed=1, env_guidance=2.0)
    late = gen.generate(["walk", "jump"], 12, anchor="reference", anchor_alpha=0.25, anchor_t_max=999, **kw).features
    every = gen.generate(["walk", "jump"], 12, anchor="reference", anchor_alpha=0.25, **kw).features
    assert torch.equal(late, every)  # every DDIM step at t <= 999
    never = gen.generate(["walk", "jump"], 12, anchor="reference", anchor_alpha=0.25, anchor_t_max=0, **kw).features
    some = gen.generate(["walk", "jump"], 12, anchor="reference", anchor_alpha=0.25, anchor_t_max=500, **kw).features
    assert not torch.allclose(never, every, atol=1e-4) and not torch.allclose(some, every, atol=1e-4)
    with pytest.raises(SimdiffError, match="anchor t max 500 needs the backbone or reference anchor"):
        gen.generate(["walk"], 12, env=envs[1], steps=2, anchor_t_max=500)
    with pytest.raises(SimdiffError, match="anchor t max must be a whole timestep in 0..999, got 1000"):
        gen.generate(["walk"], 12, env=envs[1], steps=2, anchor="reference", anchor_t_max=1000)


def test_load_pretrained_missing_folder(tmp_path) -> None:
    with pytest.raises(SimdiffError, match="config.json"):
        load_pretrained(tmp_path / "nope")


def reacting_generator() -> MotionGenerator:
    """A tiny continuous SimDiff generator whose adapters answer φ (jittered up-projections)."""
    config = tiny(True)
    torch.manual_seed(0)
    net = build_network(config)
    for a in net.adapters:
        torch.nn.init.normal_(a.up.weight, std=0.3)
    return MotionGenerator(net, config, HashText())


def test_env_guidance_changes_only_motions_off_earth_and_is_validated() -> None:
    gen = reacting_generator()
    envs = [[-9.81, 0.0, 0.0], [-1.6, 0.0, 0.0]]
    plain = gen.generate(["walk", "jump"], 12, env=envs, alpha=0.5, steps=3, seed=1).features
    pushed = gen.generate(["walk", "jump"], 12, env=envs, alpha=0.5, steps=3, seed=1, env_guidance=3.0).features
    assert torch.equal(plain[0], pushed[0]) and not torch.allclose(plain[1], pushed[1], atol=1e-4)
    for bad in (-1.0, float("nan"), float("inf")):
        with pytest.raises(SimdiffError, match="env guidance must be"):
            gen.generate(["walk"], 12, env=envs[1], steps=2, env_guidance=bad)
    backbone = MotionGenerator(build_network(tiny()), tiny(), HashText())
    with pytest.raises(SimdiffError, match="continuous Sim Encoder"):
        backbone.generate(["walk"], 12, steps=2, env_guidance=2.0)


@pytest.mark.parametrize("mask_frames", [True, False])
def test_masked_batch_gives_each_sample_at_its_own_length(mask_frames: bool) -> None:
    """With ``mask_frames`` a short sample in a padded batch is the sample its length gives alone (same noise);
    without it (MDM) the padded frames are denoised as motion too and the short sample is a crop of a longer one."""
    from simdiff.diffusion.sampling import make_scheduler, sample
    from simdiff.model.condition import Condition

    config = ModelConfig(backbone=backbone_preset("tiny", mask_frames=mask_frames), sim=SimConfig())
    torch.manual_seed(0)
    net = build_network(config).eval()
    for a in net.adapters:
        torch.nn.init.normal_(a.up.weight, std=0.3)
    text = HashText().encode(["a person walks", "a person jumps"])
    lengths = torch.tensor([20, 12])
    env = torch.tensor([[-1.6, 0.0, 0.0], [-1.6, 3.0, 0.0]])
    x_init = torch.randn(2, 20, 263, generator=torch.Generator().manual_seed(5))
    kw = dict(guidance=2.5, env_guidance=2.0)
    batch = sample(net, make_scheduler("ddim", 5), Condition(text=text, frame_mask=torch.arange(20)[None] < lengths[:, None],
                                                            env=env, alpha=0.5), 20, x_init=x_init, **kw)
    alone = sample(net, make_scheduler("ddim", 5), Condition(text=text[1:], frame_mask=torch.ones(1, 12, dtype=torch.bool),
                                                            env=env[1:], alpha=0.5), 12, x_init=x_init[1:, :12], **kw)
    assert torch.allclose(batch[1, :12], alone[0], atol=1e-4) is mask_frames
    first = sample(net, make_scheduler("ddim", 5), Condition(text=text[:1], frame_mask=torch.ones(1, 20, dtype=torch.bool),
                                                            env=env[:1], alpha=0.5), 20, x_init=x_init[:1], **kw)
    assert torch.allclose(batch[0], first[0], atol=1e-4)  # the longest sample has no padding either way


def test_ballistic_runs_last_with_each_rows_gravity_and_is_validated(monkeypatch) -> None:
    import simdiff.motion.ballistic as ballistic

    seen: dict = {}

    def lift(features, gravity, lengths, strength):  # stands in for the projection (tested on its own)
        seen.update(g=torch.as_tensor(gravity, dtype=torch.float64).reshape(-1).tolist(), lengths=lengths.tolist(),
                    strength=strength)
        out = features.clone()
        out[..., 3] += 1.0
        return out

    monkeypatch.setattr(ballistic, "ballistic_flights", lift)
    gen = reacting_generator()
    envs = [[-9.81, 0.0, 0.0], [-1.6, 0.0, 0.0]]
    plain = gen.generate(["walk", "jump"], [12, 10], env=envs, alpha=0.5, steps=2, seed=1)
    assert not seen  # off by default
    on = gen.generate(["walk", "jump"], [12, 10], env=envs, alpha=0.5, steps=2, seed=1, ballistic=0.5)
    assert seen["g"] == pytest.approx([-9.81, -1.6]) and seen["lengths"] == [12, 10] and seen["strength"] == 0.5
    assert torch.allclose(on.features[0, :, 3], plain.features[0, :, 3] + 1.0)
    assert torch.all(on.features[1, 10:] == 0)  # padding stays zero
    assert torch.allclose(on.normalized[0], (on.features[0] - gen.mean) / gen.std, atol=1e-5)
    backbone = MotionGenerator(build_network(tiny()), tiny(), HashText())
    backbone.generate(["walk"], 12, steps=2, ballistic=1.0)
    assert seen["g"] == pytest.approx([-9.81])  # a backbone-only model generates under Earth
    with pytest.raises(SimdiffError, match=r"ballistic strength must be in \[0, 1\], got 2.0"):
        gen.generate(["walk"], 12, steps=2, ballistic=2.0)
    cat = ModelConfig(backbone=backbone_preset("tiny"), sim=SimConfig(mode="categorical"))
    with pytest.raises(SimdiffError, match="ballistic flight needs gravity as a number"):
        MotionGenerator(build_network(cat), cat, HashText()).generate(["walk"], 12, env_index=1, steps=2, ballistic=1.0)
