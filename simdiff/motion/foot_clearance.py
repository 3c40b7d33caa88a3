"""Swing-foot clearance: lift a moving foot that drags along the floor, bending the knee to reach it.

A generated step often scuffs: the swinging toe sweeps forward within millimetres of the floor. The
contact hold (:mod:`simdiff.motion.contact_hold`) cannot help there, since the foot is not planted (its
contact channels are off). Here, on frames where a
foot's contact channels are both off and the foot moves faster than ``min_speed`` horizontally, the
ankle and toe are raised together (the foot keeps its shape) until both are ``clearance`` above the
motion's own floor (the 5th percentile of its lowest-joint height, as
:func:`simdiff.motion.metrics.own_floor_metrics`). The lift is spread over neighbouring frames
(a max over ±1 frame, then a 1-2-1 filter) so it eases in and out, and the knee is re-solved by
two-bone inverse kinematics (:mod:`simdiff.motion.leg_ik`): the hip stays, thigh and shin keep their lengths, and the knee bends
in the plane it bent in before. Only the position channels change (``ric`` of knee, ankle and toe
and their velocities); the root, the other joints, the contact channels and the rot6d channels are
untouched (joints are read from ``ric``, as in evaluation, rendering and export).
"""

from __future__ import annotations

import torch

from simdiff.errors import SimdiffError
from simdiff.motion.features import SLICES, features_to_joints
from simdiff.motion.contact_features import CONTACT_THRESHOLD, batch_features, yaw_rotate
from simdiff.motion.leg_ik import solve_leg
from simdiff.motion.metrics import OWN_FLOOR_PERCENTILE
from simdiff.motion.skeleton import FPS

LEGS: tuple[tuple[int, int, int, int, int, int], ...] = ((1, 4, 7, 10, 0, 1), (2, 5, 8, 11, 2, 3))
"""Per leg: hip, knee, ankle, toe joint and the ankle's and toe's contact channel (left, right)."""

CLEARANCE: float = 0.04
"""Metres above the own floor that a swinging ankle and toe are lifted to: real walks' swinging toes (faster than
0.5 m/s) are 3.9 cm above it at their 10th percentile (median over 300 corpus walks); 2 cm left a walk skate ratio
of 0.29, 4 cm 0.23 (24 generated walks)."""
MIN_SPEED: float = 0.5
"""m/s of horizontal foot speed above which an unplanted foot near the floor counts as swinging (GMD's skate
speed)."""


def _world_to_heading(half: torch.Tensor, v: torch.Tensor) -> torch.Tensor:
    """World vectors (..., 3) into the heading frame of yaw half-angle ``half`` (...) (features' convention)."""
    x, z = yaw_rotate(half, v[..., 0], v[..., 2])
    return torch.stack([x, v[..., 1], z], dim=-1)


def clear_swing_feet(features: torch.Tensor, lengths: torch.Tensor | None = None, strength: float = 1.0,
                     clearance: float = CLEARANCE, min_speed: float = MIN_SPEED) -> torch.Tensor:
    """Features whose swinging feet clear the floor (see the module docstring).

    Args:
        features: (B, T, 263) or (T, 263) un-normalised HumanML3D features (20 fps, metres, Y-up).
        lengths: (B,) valid frames (None: all T); frames past a length are returned unchanged.
        strength: share of the needed lift applied, in [0, 1].
        clearance: metres above the own floor (≥ 0); min_speed: m/s (≥ 0).
    Returns:
        Features of the same shape, dtype and device.
    """
    if not 0.0 <= strength <= 1.0:
        raise SimdiffError(f"swing-foot clearance strength must be in [0, 1], got {strength}")
    if not clearance >= 0.0 or not min_speed >= 0.0:
        raise SimdiffError(f"clearance and min_speed must be >= 0, got {clearance} and {min_speed}")
    f, single, valid = batch_features(features, lengths, "swing-foot clearance")  # valid: (B, T)
    b, t = f.shape[:2]
    joints = features_to_joints(f)  # (B, T, 22, 3)
    lowest = joints[..., 1].min(-1).values.masked_fill(~valid, float("nan"))
    floor = torch.nanquantile(lowest, OWN_FLOOR_PERCENTILE / 100.0, dim=1)  # (B,)
    planted = f[..., SLICES["contacts"]] > CONTACT_THRESHOLD  # (B, T, 4)
    half = torch.zeros_like(f[..., 0])
    half[:, 1:] = torch.cumsum(f[:, :-1, 0], dim=1)
    delta = torch.zeros_like(joints)  # (B, T, 22, 3) world displacement per joint
    forward = torch.stack([-torch.sin(2 * half), torch.zeros_like(half), torch.cos(2 * half)], dim=-1)  # +Z unrotated
    for hip, knee, ankle, toe, c_ankle, c_toe in LEGS:
        foot = joints[:, :, [ankle, toe]]  # (B, T, 2, 3)
        step = (foot[:, 1:, :, [0, 2]] - foot[:, :-1, :, [0, 2]]).norm(dim=-1).amax(-1) * FPS  # (B, T-1) m/s
        pair_ok = valid[:, 1:] & (step > min_speed)
        moving = torch.zeros_like(valid)
        moving[:, 1:] |= pair_ok
        moving[:, :-1] |= pair_ok
        swing = moving & ~planted[..., c_ankle] & ~planted[..., c_toe] & valid
        need = (floor[:, None, None] + clearance - foot[..., 1]).amax(-1).clamp_min(0) * swing  # (B, T)
        spread = torch.nn.functional.max_pool1d(need[:, None], 3, stride=1, padding=1)[:, 0] * valid
        kernel = torch.tensor([[[0.25, 0.5, 0.25]]], dtype=f.dtype, device=f.device)
        lift = torch.nn.functional.conv1d(spread[:, None], kernel, padding=1)[:, 0].maximum(need) * valid * strength
        up = torch.zeros_like(foot[:, :, 0])
        up[..., 1] = lift
        delta[:, :, ankle] = up
        delta[:, :, toe] = up
        new_knee, _ = solve_leg(joints[:, :, hip], joints[:, :, knee], joints[:, :, ankle], joints[:, :, ankle] + up,
                                forward)
        delta[:, :, knee] = torch.where(lift[..., None] > 0, new_knee - joints[:, :, knee], torch.zeros_like(up))
    ric = f[..., SLICES["ric"]].reshape(b, t, 21, 3)
    f[..., SLICES["ric"]] = (ric + _world_to_heading(half[..., None], delta[:, :, 1:])).reshape(b, t, -1)
    vel = f[:, :-1, SLICES["vel"]].reshape(b, t - 1, 22, 3)
    moved = _world_to_heading(half[:, :-1, None], delta[:, 1:] - delta[:, :-1]) * valid[:, 1:, None, None]
    f[:, :-1, SLICES["vel"]] = (vel + moved).reshape(b, t - 1, -1)
    out = f.to(features.dtype)
    return out[0] if single else out
