"""Swing-foot clearance: a foot that sweeps along the floor unplanted is lifted, the leg keeps its bone lengths."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from simdiff.errors import SimdiffError
from simdiff.motion.features import SLICES, features_to_joints, process_joints
from simdiff.motion.foot_clearance import CLEARANCE, clear_swing_feet
from simdiff.motion.metrics import own_floor_metrics

LEFT_LEG = (1, 4, 7, 10)


def _scuff(frames: int = 60) -> torch.Tensor:
    """A standing body whose left leg sweeps forward and back with the toe on the floor (≈1 m/s at the
    middle of each sweep); left contact channels off, right on."""
    from simdiff.motion.skeleton import CANONICAL_OFFSETS, PARENTS

    rest = np.zeros((22, 3))
    for j in range(1, 22):
        rest[j] = rest[PARENTS[j]] + CANONICAL_OFFSETS[j]
    rest[:, 1] -= rest[:, 1].min()
    joints = np.repeat(rest[None], frames + 1, axis=0)
    sweep = 0.15 * np.sin(np.arange(frames + 1) / 3.0)
    for j in (7, 10):  # ankle and toe slide along +-Z on the floor (the leg stretches: a scuff, not a pose)
        joints[:, j, 2] += sweep
    f = torch.as_tensor(process_joints(joints.astype(np.float32)).features)
    f[:, SLICES["contacts"]] = torch.tensor([0.0, 0.0, 1.0, 1.0])
    return f


def _speed(j: torch.Tensor, joint: int) -> torch.Tensor:
    step = (j[1:, joint, [0, 2]] - j[:-1, joint, [0, 2]]).norm(dim=-1) * 20
    return torch.cat([step, step[-1:]])


def test_swinging_foot_clears_the_floor_and_the_leg_keeps_its_lengths() -> None:
    f = _scuff()
    before = features_to_joints(f.double())
    out = clear_swing_feet(f)
    after = features_to_joints(out.double())
    fast = (_speed(before, 10) > 0.5) & (torch.cat([_speed(before, 10)[:1], _speed(before, 10)[:-1]]) > 0.5)
    assert fast.sum() > 10
    floor = 0.0  # the standing right toe is the lowest joint throughout
    assert (after[fast][:, [7, 10], 1] >= floor + CLEARANCE - 1e-4).all()
    for a, b in zip(LEFT_LEG[:-1], LEFT_LEG[1:]):  # hip-knee, knee-ankle, ankle-toe
        assert torch.allclose((after[:, a] - after[:, b]).norm(dim=-1), (before[:, a] - before[:, b]).norm(dim=-1),
                              atol=1e-5)
    others = [j for j in range(22) if j not in (4, 7, 10)]
    assert torch.allclose(after[:, others], before[:, others], atol=1e-6)
    for name in ("root_rot_vel", "root_lin_vel", "root_y", "rot6d", "contacts"):
        assert torch.equal(out[:, SLICES[name]], f[:, SLICES[name]]), name
    assert own_floor_metrics(before[None])["sliding_own_floor"] > 5.0
    assert own_floor_metrics(after[None])["sliding_own_floor"] < 0.1


def test_velocity_channels_follow_the_moved_joints() -> None:
    f = _scuff()
    out = clear_swing_feet(f)
    dv = (out - f)[:-1, SLICES["vel"]].reshape(-1, 22, 3)
    moved = features_to_joints(out.double()) - features_to_joints(f.double())  # the root does not turn: world = heading
    assert torch.allclose(dv.double(), moved[1:] - moved[:-1], atol=1e-5)
    assert dv.abs().max() > 1e-3


def test_planted_slow_or_zero_strength_feet_are_untouched() -> None:
    f = _scuff()
    assert torch.equal(clear_swing_feet(f, strength=0.0), f)
    planted = f.clone()
    planted[:, SLICES["contacts"]] = 1.0
    assert torch.equal(clear_swing_feet(planted), planted)
    assert torch.equal(clear_swing_feet(f, min_speed=5.0), f)  # nothing moves at 5 m/s
    half = clear_swing_feet(f, strength=0.5)
    full = clear_swing_feet(f)
    lift = lambda x: features_to_joints(x.double())[:, 10, 1] - features_to_joints(f.double())[:, 10, 1]  # noqa: E731
    assert torch.allclose(lift(half), lift(full) / 2, atol=1e-6)


def test_batches_with_lengths_match_single_clips_and_padding_is_kept() -> None:
    f = _scuff()
    short = _scuff(40)
    batch = torch.zeros(2, f.shape[0], 263)
    batch[0] = f
    batch[1, : short.shape[0]] = short
    batch[1, short.shape[0]:] = 7.0  # padding must come back as it was
    out = clear_swing_feet(batch, torch.tensor([f.shape[0], short.shape[0]]))
    assert torch.allclose(out[0], clear_swing_feet(f), atol=1e-6)
    assert torch.allclose(out[1, : short.shape[0] - 1], clear_swing_feet(short)[:-1], atol=1e-6)
    assert torch.equal(out[1, short.shape[0]:], batch[1, short.shape[0]:])
    assert out.dtype == batch.dtype


@pytest.mark.parametrize("kwargs, message", [({"strength": 1.5}, "strength must be in [0, 1], got 1.5"),
                                             ({"clearance": -0.01}, "must be >= 0, got -0.01"),
                                             ({"min_speed": float("nan")}, "must be >= 0")])
def test_bad_settings_are_one_line_errors(kwargs: dict, message: str) -> None:
    with pytest.raises(SimdiffError, match=message.replace("[", r"\[").replace("]", r"\]")):
        clear_swing_feet(_scuff(), **kwargs)
    with pytest.raises(SimdiffError, match="needs"):
        clear_swing_feet(torch.zeros(5, 100))


def test_turning_root_changes_are_written_in_the_heading_frame() -> None:
    """On a turning body the lift is still straight up in the world and the velocity channels follow it."""
    from simdiff.motion.foot_clearance import _world_to_heading
    from simdiff.motion.skeleton import CANONICAL_OFFSETS, PARENTS

    frames = 60
    rest = np.zeros((22, 3))
    for j in range(1, 22):
        rest[j] = rest[PARENTS[j]] + CANONICAL_OFFSETS[j]
    rest[:, 1] -= rest[:, 1].min()
    joints = np.repeat(rest[None], frames + 1, axis=0)
    joints[:, [7, 10], 2] += 0.15 * np.sin(np.arange(frames + 1) / 3.0)[:, None]
    angle = 0.03 * np.arange(frames + 1)  # the whole body turns about the pelvis' vertical axis
    c, s = np.cos(angle)[:, None], np.sin(angle)[:, None]
    x, z = joints[..., 0] - joints[:, :1, 0], joints[..., 2] - joints[:, :1, 2]
    joints[..., 0], joints[..., 2] = joints[:, :1, 0] + c * x + s * z, joints[:, :1, 2] - s * x + c * z
    f = torch.as_tensor(process_joints(joints.astype(np.float32)).features)
    f[:, SLICES["contacts"]] = torch.tensor([0.0, 0.0, 1.0, 1.0])
    assert f[:, 0].abs().min() > 1e-3  # the root turns every frame
    out = clear_swing_feet(f)
    before, after = features_to_joints(f.double()), features_to_joints(out.double())
    moved = after - before
    assert moved[..., [0, 2]][:, [7, 10]].abs().max() < 1e-6 and moved[:, 10, 1].max() > 0.01  # straight up
    half = torch.zeros(f.shape[0], dtype=torch.float64)
    half[1:] = torch.cumsum(f[:-1, 0].double(), 0)
    dv = (out - f)[:-1, SLICES["vel"]].reshape(-1, 22, 3).double()
    assert torch.allclose(dv, _world_to_heading(half[:-1, None], moved[1:] - moved[:-1]), atol=1e-5)
