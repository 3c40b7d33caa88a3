"""Foot lock: move the root so that the feet a motion says are planted stay where they are.

A generated motion carries its own foot-contact channels (HumanML3D features 259–262: left ankle, left toe,
right ankle, right toe). Where foot joints are marked in contact on two consecutive frames, the lowest of them
(the pivot: a heel at a strike, a toe at a push-off) should not move horizontally; the whole body is shifted back
by the pivot's displacement, frame by frame, so it keeps its place and the rest of the body travels over it. Only
the root's horizontal velocity changes (and, to keep the features consistent, the joint-velocity channels by the
same amount); poses, heights, the root's yaw and the contact channels are untouched, so a flight or a crouch is
exactly as generated. It is the classic root-trajectory part of foot-skate cleanup, not inverse kinematics: two
planted feet that slide apart (a split) keep the lower one in place, not both. The generator's ``foot_lock``
applies :func:`clean_feet`: this lock, then :mod:`simdiff.motion.foot_clearance` (swinging feet that drag along
the floor are lifted clear of it, the knee re-solved), both at the same strength, and lowers a
clip that never touches the floor onto it (:func:`simdiff.motion.floor.drop_floating`).
"""

from __future__ import annotations

import numpy as np
import torch

from simdiff.errors import SimdiffError
from simdiff.motion.features import SLICES, features_to_joints
from simdiff.motion.floor import drop_floating
from simdiff.motion.foot_clearance import clear_swing_feet
from simdiff.motion.contact_features import CONTACT_THRESHOLD, batch_features, yaw_rotate
from simdiff.motion.skeleton import FOOT_LEFT, FOOT_RIGHT

CONTACT_JOINTS: tuple[int, int, int, int] = (*FOOT_LEFT, *FOOT_RIGHT)
"""Joints of the four contact channels, in channel order (left ankle, left toe, right ankle, right toe)."""

CLEANUP_VERSION: int = 3
"""What the generator's ``foot_lock`` does: 1 the lock alone, 2 the lock and the swing-foot
clearance, 3 those and a floating clip dropped onto the floor (:func:`clean_feet`).
Cached measurements made with a foot lock carry it in their fingerprint."""

def lock_feet(features: torch.Tensor, lengths: torch.Tensor | None = None, strength: float = 1.0,
              planted: torch.Tensor | None = None) -> torch.Tensor:
    """Features whose planted feet do not slide (see the module docstring).

    Args:
        features: (B, T, 263) or (T, 263) un-normalised HumanML3D features (20 fps, metres, Y-up).
        lengths: (B,) valid frames (None: all T); frames past a length are returned unchanged.
        strength: share of each planted slide taken out, in [0, 1] (1: planted joints keep their place).
        planted: (B, T, 4) or (T, 4) bool, which contact joints are planted, in place of the contact channels
            (None: the channels, > :data:`CONTACT_THRESHOLD`); for experiments with other contact rules.
    Returns:
        Features of the same shape, dtype and device.
    """
    if not 0.0 <= strength <= 1.0:
        raise SimdiffError(f"foot-lock strength must be in [0, 1], got {strength}")
    f, single, valid = batch_features(features, lengths, "foot lock")
    b, t = f.shape[:2]
    joints = features_to_joints(f)  # (B, T, 22, 3)
    feet = joints[:, :, list(CONTACT_JOINTS)][..., [0, 2]]  # (B, T, 4, 2)
    if planted is None:
        planted = f[..., SLICES["contacts"]] > CONTACT_THRESHOLD  # (B, T, 4)
    else:
        if tuple(planted.shape[-2:]) != (t, 4) or planted.numel() != b * t * 4:
            raise SimdiffError(f"planted must be ({b}, {t}, 4) booleans, got {tuple(planted.shape)}")
        planted = planted.reshape(b, t, 4).to(device=f.device, dtype=torch.bool)
    both = planted[:, 1:] & planted[:, :-1] & valid[:, 1:, None]  # (B, T-1, 4): planted through the pair
    step = feet[:, 1:] - feet[:, :-1]  # (B, T-1, 4, 2)
    # The pivot: of the joints planted through the pair, the lowest one at its start (the heel at a strike, the
    # toe at a push-off); the body is moved so that it stays in place.
    height = joints[:, :-1, list(CONTACT_JOINTS), 1].masked_fill(~both, float("inf"))
    pivot = height.argmin(-1)  # (B, T-1)
    any_planted = both.any(-1, keepdim=True)
    slide = torch.gather(step, 2, pivot[..., None, None].expand(b, t - 1, 1, 2))[:, :, 0] * any_planted
    shift = -strength * slide  # world xz added to the root's step t-1 -> t
    half = torch.zeros_like(f[..., 0])
    half[:, 1:] = torch.cumsum(f[:, :-1, 0], dim=1)  # root yaw half-angle per frame, as features_to_joints
    # Root linear velocity at row t-1 is the step t-1 -> t in the frame of yaw(t).
    dx, dz = yaw_rotate(half[:, 1:], shift[..., 0], shift[..., 1])
    f[:, :-1, 1] += dx
    f[:, :-1, 2] += dz
    # Joint velocities at row t-1 (the step t-1 -> t of every joint, in the frame of yaw(t-1)): the same shift.
    vx, vz = yaw_rotate(half[:, :-1], shift[..., 0], shift[..., 1])
    vel = f[:, :-1, SLICES["vel"]].reshape(b, t - 1, -1, 3).clone()  # a copy: with T = 2 the reshape is a view
    vel[..., 0] += vx[..., None]
    vel[..., 2] += vz[..., None]
    f[:, :-1, SLICES["vel"]] = vel.reshape(b, t - 1, -1)
    out = f.to(features.dtype)
    return out[0] if single else out


def clean_feet(features: torch.Tensor, lengths: torch.Tensor | None = None, strength: float = 1.0) -> torch.Tensor:
    """The generator's foot cleanup at ``strength``: planted feet locked (:func:`lock_feet`), then swinging feet
    lifted clear of the floor (:func:`simdiff.motion.foot_clearance.clear_swing_feet`), then, whatever the
    strength > 0, a clip that never comes within 0.10 m of the floor lowered onto it
    (:func:`simdiff.motion.floor.drop_floating`; clips that touch it are not moved). Shapes as :func:`lock_feet`."""
    cleaned = clear_swing_feet(lock_feet(features, lengths, strength), lengths, strength)
    return drop_floating(cleaned, lengths) if strength > 0 else cleaned


def lock_feet_numpy(features: np.ndarray, strength: float = 1.0) -> np.ndarray:
    """:func:`lock_feet` for one (T, 263) numpy clip (float32 out)."""
    return lock_feet(torch.as_tensor(np.asarray(features, dtype=np.float32)), strength=strength).numpy()


def clean_feet_numpy(features: np.ndarray, strength: float = 1.0) -> np.ndarray:
    """:func:`clean_feet` for one (T, 263) numpy clip (float32 out)."""
    return clean_feet(torch.as_tensor(np.asarray(features, dtype=np.float32)), strength=strength).numpy()
