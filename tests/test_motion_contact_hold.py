"""Planted feet held by leg IK: the pivot stays put, the root and every non-leg joint are untouched, bones keep
their lengths, and corrections fade without jumps."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from simdiff.diffusion.config import SamplingConfig
from simdiff.errors import SimdiffError
from simdiff.motion.contact_hold import LEGS, RELEASE_FRAMES, hold_contacts, hold_offsets
from simdiff.motion.features import SLICES, process_joints
from simdiff.motion.foot_lock import clean_feet
from simdiff.motion.rigid import bone_lengths, joints_from_features, rigidify

LEG_JOINTS = sorted({j for leg in LEGS for j in leg[1:]})


def _skating_walk(frames: int = 40, speed: float = 0.03) -> np.ndarray:
    """A rigid body that glides forward at ``speed`` m/frame with knees bent, swinging its left leg; the right foot
    skates along the floor the whole time."""
    from simdiff.motion.skeleton import CANONICAL_OFFSETS, PARENTS

    rest = np.zeros((22, 3))
    for j in range(1, 22):
        rest[j] = rest[PARENTS[j]] + CANONICAL_OFFSETS[j]
    joints = np.repeat(rest[None], frames, axis=0)
    t = np.arange(frames)
    for knee, ankle, toe in ((4, 7, 10), (5, 8, 11)):  # knees a little forward: bent legs
        joints[:, knee, 2] += 0.06
    joints[:, [4, 7, 10], 2] += 0.08 * np.sin(t / 4.0)[:, None]  # the left leg swings
    joints[:, :, 2] += speed * t[:, None]  # glide along +Z (facing)
    joints = rigidify(joints, None)  # exact constant bones
    joints[:, :, 1] -= joints[:, :, 1].min()
    return joints


def _planted(frames: int, left: bool = False, right: bool = True) -> np.ndarray:
    flags = np.zeros((frames, 4), dtype=bool)
    flags[:, :2] = left
    flags[:, 2:] = right
    return flags


def test_a_planted_foot_stays_put_and_only_leg_joints_move() -> None:
    joints = _skating_walk()
    out = hold_contacts(joints, _planted(len(joints)))
    pivot = out[:, 11] if joints[0, 11, 1] < joints[0, 8, 1] else out[:, 8]  # the lower of the right ankle and toe
    slide = np.linalg.norm(np.diff(pivot[:, [0, 2]], axis=0), axis=-1)
    reach = np.linalg.norm(out[:, 8] - out[:, 2], axis=-1) < 0.999 * (
        np.linalg.norm(joints[0, 5] - joints[0, 2]) + np.linalg.norm(joints[0, 8] - joints[0, 5]))
    assert slide[reach[1:] & reach[:-1]].max() < 1e-4  # in reach: pinned
    assert np.abs(np.diff(joints[:, 11, [0, 2]], axis=0)).max() > 0.02  # before: 3 cm per frame of skate
    others = [j for j in range(22) if j not in LEG_JOINTS]
    assert np.array_equal(out[:, others], joints[:, others].astype(np.float32))
    assert np.array_equal(out[:, [4, 7, 10]], joints[:, [4, 7, 10]].astype(np.float32))  # the left leg is free
    assert bone_lengths(out).std(axis=0).max() < 1e-5  # rigid in, rigid out
    assert np.allclose(out[:, 11] - out[:, 8], joints[:, 11] - joints[:, 8], atol=1e-5)  # the foot keeps its shape


def test_out_of_reach_straightens_the_leg_and_never_stretches_it() -> None:
    joints = _skating_walk(frames=60, speed=0.05)  # 3 m of skate: far beyond a leg
    out = hold_contacts(joints, _planted(len(joints)))
    legs = np.linalg.norm(out[:, 8] - out[:, 2], axis=-1)
    full = np.linalg.norm(joints[0, 5] - joints[0, 2]) + np.linalg.norm(joints[0, 8] - joints[0, 5])
    assert legs.max() <= full + 1e-6 and legs.max() > 0.99 * full
    assert bone_lengths(out).std(axis=0).max() < 1e-5


def test_a_lifted_foot_fades_back_without_a_jump() -> None:
    joints = _skating_walk(frames=40, speed=0.01)
    planted = _planted(len(joints))
    planted[20:, 2:] = False  # lifts at frame 20, 19 cm behind where it would be
    out = hold_contacts(joints, planted)
    shift = out[:, 8] - joints[:, 8]
    assert np.linalg.norm(shift[19]) > 0.15
    assert np.allclose(shift[20 + RELEASE_FRAMES - 1:], 0.0, atol=1e-6)
    step = np.linalg.norm(np.diff(out[:, 8], axis=0), axis=-1)
    assert step[19:24].max() < np.linalg.norm(shift[19]) / RELEASE_FRAMES + 0.02  # spread over the release frames


def test_a_new_pivot_starts_where_the_foot_is_no_jump_at_the_roll() -> None:
    feet = np.zeros((6, 2, 2))
    feet[:, 0, 0] = np.arange(6) * 0.01  # the heel slides 1 cm per frame
    feet[:, 1, 0] = 0.15 + np.arange(6) * 0.01
    heights = np.tile([0.0, 0.02], (6, 1))
    heights[2] = [0.01, 0.0]  # the toe comes down lower, but the heel is still planted: it stays the pivot
    heights[3:] = [0.05, 0.0]
    planted = np.ones((6, 2), dtype=bool)
    planted[3:, 0] = False  # the roll: the heel lifts, the toe takes over
    shift = hold_offsets(feet, heights, planted)
    assert np.allclose(feet[:3, 0, 0] + shift[:3, 0], 0.0)  # the heel pinned
    assert np.allclose(np.diff(feet[3:, 1, 0] + shift[3:, 0]), 0.0)  # then the toe, from where it was
    assert np.abs(np.diff(shift, axis=0)).max() <= 0.0100001


def test_strength_zero_nothing_planted_and_bad_input() -> None:
    joints = _skating_walk()
    assert np.array_equal(hold_contacts(joints, _planted(len(joints)), 0.0), joints.astype(np.float32))
    assert np.array_equal(hold_contacts(joints, _planted(len(joints), right=False)), joints.astype(np.float32))
    half = hold_contacts(joints, _planted(len(joints)), 0.5)
    full = hold_contacts(joints, _planted(len(joints)))
    assert np.abs(half[:, 8] - joints[:, 8]).max() < np.abs(full[:, 8] - joints[:, 8]).max()
    with pytest.raises(SimdiffError, match=r"\(40, 4\) contact flags"):
        hold_contacts(joints, _planted(len(joints))[:, :2])
    with pytest.raises(SimdiffError, match=r"\(T, 22, 3\) joints"):
        hold_contacts(joints[:, :20], _planted(len(joints)))
    with pytest.raises(SimdiffError, match=r"strength must be in \[0, 1\], got 2"):
        hold_contacts(joints, _planted(len(joints)), 2.0)


def test_written_joints_hold_the_feet_their_features_mark_planted() -> None:
    joints = _skating_walk(frames=41, speed=0.005)  # 20 cm of skate: within a leg's reach
    features = process_joints(joints.astype(np.float32)).features
    features[:, SLICES["contacts"]] = [0.0, 0.0, 1.0, 1.0]  # the right foot marked planted throughout
    free = joints_from_features(features)
    held = joints_from_features(features, 1.0)
    assert np.allclose(held[:, 0], free[:, 0])  # the root keeps its path
    assert np.abs(np.diff(held[:, 11, [0, 2]], axis=0)).max() < 1e-3 < np.abs(np.diff(free[:, 11, [0, 2]], axis=0)).max()
    assert bone_lengths(held).std(axis=0).max() < 1e-4


def test_generator_cleanup_runs_the_feature_passes_on_the_final_sample() -> None:
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


def test_a_correction_never_exceeds_the_cap() -> None:
    from simdiff.motion.contact_hold import MAX_HOLD

    feet = np.zeros((30, 2, 2))
    feet[:, :, 1] = np.arange(30)[:, None] * 0.05  # 1.5 m of skate while planted
    shift = hold_offsets(feet, np.zeros((30, 2)), np.ones((30, 2), dtype=bool))
    assert np.linalg.norm(shift, axis=-1).max() == pytest.approx(MAX_HOLD)
    assert np.allclose(np.diff(feet[10:, 0, 1] + shift[10:, 1]), 0.05)  # beyond the cap the foot slides on
