"""PhysDiff baseline: projection schedule, substitution of x̂₀, re-encoding."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from simdiff.baselines.physdiff import (PhysDiffConfig, ProjectionHook, check_schedule, end_schedule, physdiff_generate,
                                        reencode)
from simdiff.diffusion.sampling import make_scheduler
from simdiff.errors import SimdiffError
from simdiff.model import ModelConfig, backbone_preset, build_network
from simdiff.inference.generator import MotionGenerator
from simdiff.motion.features import extend_last_frame, features_to_joints, process_joints
from simdiff.motion.synthetic import walk
from simdiff.train.testing import HashTextEncoder


class LiftProjector:
    """Fake simulator: lifts every motion 5 cm and records what it was asked."""

    def __init__(self) -> None:
        self.calls: list[tuple[list[int], list[tuple]]] = []

    def __call__(self, motions, envs):
        self.calls.append(([len(m) for m in motions], [e.as_tuple() for e in envs]))
        for m in motions:
            yield np.asarray(m) + np.array([0.0, 0.05, 0.0]), {"success": True}


def tiny_generator(seed: int = 0) -> MotionGenerator:
    torch.manual_seed(seed)
    config = ModelConfig(backbone=backbone_preset("tiny"))
    rng = np.random.default_rng(seed)
    mean = torch.from_numpy(process_joints(walk(40)).features.mean(0))
    std = torch.from_numpy(rng.uniform(0.05, 0.3, 263).astype(np.float32))
    return MotionGenerator(build_network(config), config, HashTextEncoder(), mean, std)


def test_end4_space1_is_60_40_20_0_for_ddim50() -> None:
    assert end_schedule(make_scheduler("ddim", 50).timesteps) == [60, 40, 20, 0]
    assert end_schedule(make_scheduler("ddim", 50).timesteps, 4, 2) == [120, 80, 40, 0]  # ends on the final step
    assert check_schedule("ddpm", None, (0, 20, 40, 60)) == [60, 40, 20, 0]
    with pytest.raises(SimdiffError, match="not a step"):
        check_schedule("ddim", 50, (61,))


@pytest.mark.parametrize("sampler", ["ddim", pytest.param("ddpm", marks=pytest.mark.slow)])  # DDPM-1000: ~10-100 s
def test_projection_happens_exactly_at_scheduled_steps_and_is_used(sampler: str) -> None:
    gen = tiny_generator()
    proj = LiftProjector()
    seen: list[tuple[int, torch.Tensor, torch.Tensor]] = []
    config = PhysDiffConfig(sampler=sampler, env=(-3.0, 0.0, 0.0), guidance=1.0)

    # wrap the hook to see what it returned and the x_t the sampler then gave it
    import simdiff.baselines.physdiff as P

    original = P.ProjectionHook.__call__

    def spy(self, x0, t, x_t):
        out = original(self, x0, t, x_t)
        seen.append((t, out.clone(), x_t.clone()))
        return out

    P.ProjectionHook.__call__ = spy
    try:
        generation, hook = physdiff_generate(gen, ["a person walks", "a person jumps"], [24, 16], config,
                                             projector=proj, seed=1)
    finally:
        P.ProjectionHook.__call__ = original
    assert [e["t"] for e in hook.log] == [60, 40, 20, 0]
    assert [t for t, _, _ in seen] == [60, 40, 20, 0]
    assert len(proj.calls) == 4
    assert proj.calls[0] == ([25, 17], [(-3.0, 0.0, 0.0)] * 2)  # L rows -> L+1 joint frames
    # the output is the x0 substituted at t = 0 (valid frames)
    for i, n in enumerate([24, 16]):
        assert torch.allclose(generation.normalized[i, :n], seen[-1][1][i, :n], atol=1e-5)
    if sampler == "ddim":  # consecutive steps: x_40 = DDIM(x0' at 60, x_60)
        sched = make_scheduler("ddim", None)
        expected = sched.step(seen[0][1], 60, seen[0][2]).prev_sample
        assert torch.allclose(seen[1][2], expected, atol=1e-5)
    # padding frames are never written by the projection
    assert torch.all(generation.features[1, 16:] == 0)


def test_respaced_ddpm_projects_on_its_last_steps() -> None:
    at = end_schedule(make_scheduler("ddpm", 50).timesteps)
    proj = LiftProjector()
    config = PhysDiffConfig(sampler="ddpm", steps=50, project_at=tuple(at), guidance=1.0)
    generation, hook = physdiff_generate(tiny_generator(), ["a person walks"], 12, config, projector=proj, seed=0)
    assert [e["t"] for e in hook.log] == at and at[-1] == 0 and len(proj.calls) == 4
    assert generation.features.shape == (1, 12, 263)


def test_output_is_the_reencoded_rollout() -> None:
    gen = tiny_generator(1)

    class Keep(LiftProjector):
        def __call__(self, motions, envs):
            self.last = [np.asarray(m) + np.array([0.0, 0.05, 0.0]) for m in motions]
            yield from super().__call__(motions, envs)

    proj = Keep()
    generation, _ = physdiff_generate(gen, ["a person walks"], 20, PhysDiffConfig(guidance=1.0), projector=proj, seed=0)
    expected = reencode(proj.last[0])
    assert expected.shape == (20, 263)
    assert np.allclose(generation.features[0].numpy(), expected, atol=1e-4)


def test_reencode_round_trip_of_a_clean_motion() -> None:
    feats = process_joints(walk(50)).features
    joints = extend_last_frame(np.asarray(features_to_joints(feats)), feats)
    again = reencode(joints)
    assert again.shape == feats.shape
    assert np.allclose(again[:, :67], feats[:, :67], atol=1e-4)


def test_hook_keeps_prediction_beyond_a_fall() -> None:
    gen = tiny_generator()
    normalizer = __import__("simdiff.motion.normalize", fromlist=["Normalizer"]).Normalizer(gen.mean.numpy(), gen.std.numpy())

    def falls(motions, envs):
        for m in motions:
            yield np.asarray(m)[:6], {"success": False}

    from simdiff.sim.env import Environment

    hook = ProjectionHook(normalizer, [20], Environment(), falls)
    x0 = torch.randn(1, 20, 263)
    out = hook(x0, 0, x0)
    assert torch.equal(out[0, 5:], x0[0, 5:])
    assert not torch.equal(out[0, :5], x0[0, :5])
    assert hook.log[0]["samples"][0] == {"success": False, "frames_replaced": 5, "attempts": 1, "fallback": False,
                                         "error": None}
