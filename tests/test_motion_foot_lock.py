"""Foot lock: the planted pivot keeps its place, only the root's horizontal path (and joint velocities) change."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from simdiff.diffusion.config import SamplingConfig
from simdiff.errors import SimdiffError
from simdiff.motion.features import SLICES, features_to_joints, process_joints
from simdiff.motion.foot_lock import CONTACT_JOINTS, clean_feet, lock_feet, lock_feet_numpy


def _clip(frames: int = 40, speed: float = 0.03) -> np.ndarray:
    """A body that glides forward at ``speed`` m/frame while swinging its left leg: pure foot skate."""
    from simdiff.motion.skeleton import CANONICAL_OFFSETS, PARENTS

    rest = np.zeros((22, 3))
    for j in range(1, 22):
        rest[j] = rest[PARENTS[j]] + CANONICAL_OFFSETS[j]
    rest[:, 1] -= rest[:, 1].min()
    joints = np.repeat(rest[None], frames + 1, axis=0)
    t = np.arange(frames + 1)
    joints[:, :, 2] += speed * t[:, None]  # glide along +Z (facing)
    swing = 0.1 * np.sin(t / 4.0)
    for j in (4, 7, 10):  # left knee, ankle, toe swing forward and back
        joints[:, j, 2] += swing * (1 + (j > 4))
    return process_joints(joints.astype(np.float32)).features


def _pivot_steps(f: torch.Tensor) -> torch.Tensor:
    joints = features_to_joints(f.double())
    planted = f[..., SLICES["contacts"]] > 0.5
    both = planted[1:] & planted[:-1]
    height = joints[:-1, list(CONTACT_JOINTS), 1].masked_fill(~both, float("inf"))
    pivot = height.argmin(-1)
    feet = joints[:, list(CONTACT_JOINTS)][..., [0, 2]]
    step = (feet[1:] - feet[:-1])[torch.arange(len(pivot)), pivot]
    return step[both.any(-1)].norm(dim=-1)


def test_planted_pivot_keeps_its_place_and_the_pose_is_untouched() -> None:
    f = torch.as_tensor(_clip())
    planted = f[..., SLICES["contacts"]] > 0.5
    assert planted[:, 2:].all()  # the right foot glides at 3 cm/frame, under the contact threshold
    before = _pivot_steps(f)
    assert before.min() > 0.005 and before.mean() > 0.02
    out = lock_feet(f)
    assert _pivot_steps(out).max() < 1e-5
    for name in ("root_rot_vel", "root_y", "ric", "rot6d", "contacts"):
        assert torch.equal(out[..., SLICES[name]], f[..., SLICES[name]]), name
    assert torch.equal(out[-1], f[-1])  # the last row's steps lie past the clip
    # The joint-velocity channels stay the root-facing frame differences of the locked joints.
    joints = features_to_joints(out.double())
    redo = process_joints(np.concatenate([joints.numpy(), joints.numpy()[-1:]]).astype(np.float32)).features
    vel = SLICES["vel"]
    assert np.abs(out[:-1, vel].numpy() - redo[:-1, vel]).max() < 1e-4


def test_strength_off_and_unplanted_frames() -> None:
    f = torch.as_tensor(_clip())
    assert torch.equal(lock_feet(f, strength=0.0), f)
    half = lock_feet(f, strength=0.5)
    root = lambda x: features_to_joints(x.double())[:, 0, [0, 2]]  # noqa: E731
    assert torch.allclose(root(half), (root(f) + root(lock_feet(f))) / 2, atol=1e-5)  # linear in the strength
    none = f.clone()
    none[..., SLICES["contacts"]] = 0.0
    assert torch.equal(lock_feet(none), none)  # nothing planted: nothing moves


def test_batch_lengths_dtype_and_errors() -> None:
    f = torch.as_tensor(_clip()).float()
    batch = torch.stack([f, f])
    padded = batch.clone()
    padded[1, 30:] = 0.0
    out = lock_feet(padded, torch.tensor([40, 30]))
    assert out.dtype == torch.float32 and out.shape == padded.shape
    assert torch.allclose(out[0], lock_feet(f), atol=1e-6)
    assert torch.equal(out[1, 30:], padded[1, 30:])
    assert torch.allclose(out[1, :29], lock_feet(f[:30])[:29], atol=1e-6)
    assert isinstance(lock_feet_numpy(f.numpy()), np.ndarray)
    with pytest.raises(SimdiffError, match="strength must be in"):
        lock_feet(f, strength=1.5)
    with pytest.raises(SimdiffError, match="263"):
        lock_feet(f[:, :100])


def test_generator_applies_the_lock_to_the_final_sample() -> None:
    from simdiff.model.checkpoint import build_network
    from simdiff.model.config import ModelConfig, backbone_preset
    from simdiff.inference.generator import MotionGenerator
    from simdiff.train.testing import HashTextEncoder

    torch.manual_seed(0)
    config = ModelConfig(backbone=backbone_preset("tiny"), sim=None)
    gen = MotionGenerator(build_network(config), config, HashTextEncoder())
    a = gen.generate(["walk"] * 2, [24, 16], SamplingConfig(steps=3), seed=1)
    b = gen.generate(["walk"] * 2, [24, 16], SamplingConfig(steps=3, foot_lock=1.0), seed=1)
    lens = torch.tensor([24, 16])
    valid = torch.arange(24)[None, :, None] < lens[:, None, None]
    assert torch.allclose(b.features, clean_feet(a.features, lens) * valid, atol=1e-5)
    mask = torch.arange(24)[None] < lens[:, None]
    assert torch.allclose((b.normalized * gen.std + gen.mean)[mask], b.features[mask], atol=1e-4)
    assert torch.equal(b.normalized[~mask], a.normalized[~mask])


def test_clean_feet_locks_then_clears_at_one_strength() -> None:
    from simdiff.motion.foot_clearance import clear_swing_feet

    f = torch.as_tensor(_clip())
    f[:, SLICES["contacts"].start : SLICES["contacts"].start + 2] = 0.0  # the left leg swings unplanted: it is lifted after the lock
    for s in (0.0, 0.5, 1.0):
        assert torch.allclose(clean_feet(f, strength=s), clear_swing_feet(lock_feet(f, strength=s), strength=s))
    assert not torch.allclose(clean_feet(f), lock_feet(f), atol=1e-4)


def test_an_explicit_planted_mask_replaces_the_channels() -> None:
    f = torch.as_tensor(_clip())
    channels = f[..., SLICES["contacts"]] > 0.5
    assert torch.equal(lock_feet(f, planted=channels), lock_feet(f))
    assert torch.equal(lock_feet(f, planted=torch.zeros_like(channels)), f)  # nothing planted: nothing moves
    with pytest.raises(SimdiffError, match=r"planted must be \(1, 40, 4\) booleans, got \(40, 2\)"):
        lock_feet(f, planted=channels[:, :2])
