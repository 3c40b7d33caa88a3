"""Planted feet held in place by leg inverse kinematics; the root keeps its path.

A motion's foot-contact flags say when each foot is planted (HumanML3D features 259–262: left ankle, left toe,
right ankle, right toe). While a foot is planted, one planted joint (the pivot: the lower one when the foot
lands, kept while it stays planted, so the heel at a strike and the toe once the heel lifts) is pinned where it
was planted; the foot (ankle and toe together) is translated by the pivot's
horizontal slide taken back, and the hip–knee–ankle chain is re-solved with two-bone IK (:mod:`simdiff.motion.leg_ik`) to reach the moved ankle,
the knee bending in the plane it had. When the foot lifts, the correction fades out over :data:`RELEASE_FRAMES`
frames of swing, so nothing jumps. Only the four leg joints (knee, ankle, toe per side) of frames near a contact
move: the root, the spine, the arms and the thigh, shin and foot lengths are exactly as given, so a rigid motion
stays rigid. A correction never exceeds :data:`MAX_HOLD`, and a target out of the leg's reach is met as far as the
straight leg allows (the rest of that slide remains). Joints are (T, 22, 3) metres, Y up, HumanML3D order, 20 fps.
"""

from __future__ import annotations

import numpy as np
import torch

from simdiff.errors import SimdiffError
from simdiff.motion.leg_ik import solve_leg
from simdiff.motion.skeleton import NUM_JOINTS

LEGS: tuple[tuple[int, int, int, int], tuple[int, int, int, int]] = ((1, 4, 7, 10), (2, 5, 8, 11))
"""(hip, knee, ankle, toe) of the left and right leg; the contact channels are (left ankle, left toe, right ankle,
right toe), so leg k owns channels 2k and 2k + 1."""
MAX_HOLD: float = 0.25
"""Metres: the largest correction; a planted foot that slid further drags its anchor along. Uncapped, the leg
lunging after a far anchor raised the fastest joint of 24 generated runs from 11.5 to 13.1 m/s; 0.25 m keeps it at
11.5 (walk skate ratio 0.23 → 0.27)."""
RELEASE_FRAMES: int = 4
"""Frames (0.2 s) over which a lifted foot's correction fades to zero: short enough to be gone before the next
strike of a run (swing ≥ 6 frames in the corpus), long enough that the swing foot moves ≤ 1/4 of it per frame."""


def hold_offsets(feet_xz: np.ndarray, heights: np.ndarray, planted: np.ndarray) -> np.ndarray:
    """(T, 2) horizontal correction of one foot per frame.

    Args:
        feet_xz: (T, 2, 2) x, z of the foot's (ankle, toe) in metres.
        heights: (T, 2) their heights, to pick the pivot (the lower planted joint).
        planted: (T, 2) bool contact flags of (ankle, toe).
    """
    frames = feet_xz.shape[0]
    out = np.zeros((frames, 2))
    cur = np.zeros(2)
    released = np.zeros(2)
    anchor = np.zeros(2)
    pivot, since = -1, RELEASE_FRAMES
    for t in range(frames):
        if planted[t].any():
            # the pivot stays while it is planted (switching at every near-tie of heel and toe height leaked slide)
            p = pivot if pivot >= 0 and planted[t, pivot] else int(np.argmin(np.where(planted[t], heights[t], np.inf)))
            if p != pivot:  # a new pivot is pinned where it is now, corrected: no jump at a heel-to-toe roll
                anchor, pivot = feet_xz[t, p] + cur, p
            cur = anchor - feet_xz[t, p]
            size = float(np.hypot(*cur))
            if size > MAX_HOLD:  # the anchor is dragged along: the foot slides, the leg does not lunge after it
                cur *= MAX_HOLD / size
                anchor = feet_xz[t, p] + cur
            released, since = cur.copy(), 0
        else:
            pivot, since = -1, since + 1
            cur = released * max(0.0, 1.0 - since / RELEASE_FRAMES)
        out[t] = cur
    return out


def hold_contacts(joints: np.ndarray, planted: np.ndarray, strength: float = 1.0) -> np.ndarray:
    """Joints (T, 22, 3) float32 whose planted feet stay put (module docstring).

    Args:
        joints: (T, 22, 3) positions in metres.
        planted: (T, 4) contact flags (left ankle, left toe, right ankle, right toe); bool or 0/1.
        strength: share of each slide taken back, in [0, 1].
    """
    joints = np.asarray(joints, dtype=np.float64)
    planted = np.asarray(planted) > 0.5
    if joints.ndim != 3 or joints.shape[1:] != (NUM_JOINTS, 3):
        raise SimdiffError(f"a contact hold needs (T, 22, 3) joints, got {joints.shape}")
    if planted.shape != (joints.shape[0], 4):
        raise SimdiffError(f"a contact hold needs ({joints.shape[0]}, 4) contact flags, got {planted.shape}")
    if not 0.0 <= strength <= 1.0:
        raise SimdiffError(f"contact-hold strength must be in [0, 1], got {strength}")
    out = joints.copy()
    across = joints[:, 2] - joints[:, 1]  # left hip → right hip
    forward = np.cross(np.array([0.0, 1.0, 0.0]), across)  # facing direction; knees bend this way
    for side, (hip, knee, ankle, toe) in enumerate(LEGS):
        feet = joints[:, [ankle, toe]]
        shift = strength * hold_offsets(feet[..., [0, 2]], feet[..., 1], planted[:, 2 * side:2 * side + 2])
        moved = np.flatnonzero(np.abs(shift).sum(-1) > 0)
        if moved.size == 0:
            continue
        target = joints[moved, ankle] + np.stack([shift[moved, 0], np.zeros(moved.size), shift[moved, 1]], -1)
        leg = [torch.from_numpy(a) for a in (joints[moved, hip], joints[moved, knee], joints[moved, ankle], target,
                                             forward[moved])]
        new_knee, new_ankle = (a.numpy() for a in solve_leg(*leg))
        out[moved, knee] = new_knee
        out[moved, toe] = joints[moved, toe] + (new_ankle - joints[moved, ankle])
        out[moved, ankle] = new_ankle
    return out.astype(np.float32)
