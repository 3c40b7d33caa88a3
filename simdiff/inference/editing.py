"""Edits of a user's motion with the model, in the user's own frame and skeleton: re-played under another φ
(:func:`edit_motion`) or one half of the body kept and the other made anew (:func:`keep_half`)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from simdiff.diffusion.config import SamplingConfig
from simdiff.errors import SimdiffError
from simdiff.motion.skeleton import NUM_JOINTS

if TYPE_CHECKING:
    from simdiff.inference.generator import MotionGenerator

MIN_EDIT_FRAMES: int = 10
"""Shortest motion ``simdiff edit`` takes (0.5 s at 20 fps), as ``generate``'s shortest."""


@dataclass(frozen=True)
class EditedMotion:
    """A motion re-played under φ.

    Attributes:
        joints: (T, 22, 3) float32 metres, Y up, 20 fps, in the input's frame, on the input's own skeleton.
        features: (T, 263) float32 un-normalised HumanML3D features of the edit (canonical frame, one row per
            joint frame).
        changed_m: mean joint displacement from the input, metres.
    """

    joints: np.ndarray
    features: np.ndarray
    changed_m: float


def check_motion(joints: np.ndarray, name: str = "the motion") -> np.ndarray:
    """``joints`` as float64 (T, 22, 3), T ≥ :data:`MIN_EDIT_FRAMES`, finite, bones of a body in metres (averaging
    0.02..1 m); one-line errors otherwise."""
    joints = np.asarray(joints, dtype=np.float64)
    if joints.ndim != 3 or joints.shape[1:] != (NUM_JOINTS, 3):
        raise SimdiffError(f"{name} must be (T, 22, 3) joints, got shape {joints.shape}")
    if joints.shape[0] < MIN_EDIT_FRAMES:
        raise SimdiffError(f"{name} has {joints.shape[0]} frames; editing needs at least {MIN_EDIT_FRAMES} (0.5 s)")
    if not np.all(np.isfinite(joints)):
        raise SimdiffError(f"{name} contains NaN or infinite values")
    from simdiff.motion.rigid import bone_lengths

    mean_bone = float(bone_lengths(joints).mean())
    if not 0.02 <= mean_bone <= 1.0:  # a human's 21 bones average about 0.15 m
        raise SimdiffError(f"{name}'s bones average {mean_bone:.3g} m; not a body in metres")
    return joints


def edit_motion(generator: MotionGenerator, joints: np.ndarray, config: SamplingConfig, env: Sequence[float], *,
                seed: int = 0, text: str = "", progress=None) -> EditedMotion:
    """Re-play ``joints`` (T, 22, 3) metres, Y up, 20 fps under φ = ``env`` (g_z m/s², w_x N, w_y N).

    The model's answer to φ (:func:`simdiff.inference.replay.replay_features`, canonical frame, HumanML3D skeleton)
    is turned back into the input's frame and scale and added to its joints (smoothed like every written motion,
    :func:`simdiff.motion.rigid.smooth_positions`); the sum is fitted with rotations on the input's own skeleton
    and, where φ changed something, its planted feet are held by leg IK at ``config.foot_lock``. At Earth without
    wind the input comes back (rigidly fitted). ``progress`` as :func:`~simdiff.inference.replay.replay_features`'.
    """
    from simdiff.inference.replay import replay_features
    from simdiff.motion import quaternion as Q
    from simdiff.motion.contact_hold import hold_contacts
    from simdiff.motion.features import (
        SLICES,
        extend_last_frame,
        facing_rotation,
        features_to_joints,
        process_joints,
        uniform_scale,
    )
    from simdiff.motion.rigid import fit, rest_offsets, smooth_positions

    joints = check_motion(joints)
    features = process_joints(joints).features
    replay = replay_features(generator, features, config, env, seed=seed, text=text, progress=progress)
    edited = np.concatenate([replay.features, replay.features[-1:]])
    offsets = rest_offsets(joints)
    if not replay.difference.any():
        out = fit(joints, offsets).joints
        return EditedMotion(out, edited, float(np.linalg.norm(out - joints, axis=-1).mean()))

    def decode(f: np.ndarray) -> np.ndarray:
        return extend_last_frame(features_to_joints(f), f).astype(np.float64)

    delta = decode(replay.features) - decode(features)  # canonical frame, HumanML3D skeleton
    back = Q.qinv(facing_rotation(joints))
    delta = Q.qrot(np.broadcast_to(back, delta.shape[:-1] + (4,)), delta) / uniform_scale(joints)
    moved = fit(joints + smooth_positions(delta), offsets).joints
    out = hold_contacts(moved, edited[:, SLICES["contacts"]], config.foot_lock) if config.foot_lock else moved
    out = np.asarray(out, dtype=np.float32)
    return EditedMotion(out, edited.astype(np.float32), float(np.linalg.norm(out - joints, axis=-1).mean()))


HALVES: tuple[str, ...] = ("lower", "upper")
"""What ``simdiff edit --keep`` can keep (:data:`simdiff.motion.skeleton.LOWER_BODY` / ``UPPER_BODY``)."""


def keep_half(generator: MotionGenerator, joints: np.ndarray, config: SamplingConfig, env: Sequence[float] | None,
              half: str, text: str, *, seed: int = 0, progress=None) -> EditedMotion:
    """``joints`` (T, 22, 3) with one half of the body (``half`` in :data:`HALVES`) kept and the other made anew for
    ``text`` under φ = ``env`` (None: a backbone-only model): the kept joints are keyframes
    (:func:`simdiff.inference.keyframes.sample_keyframed`) and the result is fitted on the input's skeleton, which
    holds the kept joints within 2 cm (on 4 val walks: 0.4 cm for kept legs, 1.5 cm for a kept upper body).

    A motion longer than 196 frames is made in windows (:func:`simdiff.inference.replay.windows`, seed + k for
    window k): each later window also has the whole body of its overlap with the one before as keyframes, and the two
    are cross-faded over that overlap, so the new half continues across the seam."""
    from simdiff.inference.keyframes import sample_keyframed
    from simdiff.inference.replay import windows
    from simdiff.motion.features import process_joints
    from simdiff.motion.rigid import rest_offsets, rigidify
    from simdiff.motion.skeleton import LOWER_BODY, UPPER_BODY

    if half not in HALVES:
        raise SimdiffError(f"--keep must be one of {', '.join(HALVES)}, got {half!r}")
    joints = check_motion(joints)
    kept = list(LOWER_BODY if half == "lower" else UPPER_BODY)
    skeleton, embedding = rest_offsets(joints), generator.encode_text([text])
    out = np.zeros_like(joints, dtype=np.float64)
    done = 0  # frames of ``out`` made so far
    spans = windows(len(joints))
    for k, (s, e) in enumerate(spans):
        keys = np.full((e - s, *joints.shape[1:]), np.nan)
        keys[:, kept] = joints[s:e, kept]
        keys[: done - s] = out[s:done]  # the overlap with the window before, whole body
        _, part = sample_keyframed(generator, keys, config, text_embeddings=embedding,
                                   env=None if env is None else tuple(env), seed=seed + k, skeleton=skeleton,
                                   progress=progress)
        fade = np.linspace(0.0, 1.0, done - s + 2)[1:-1, None, None]  # 0 → 1 over the overlap, ends excluded
        out[s:done] = (1.0 - fade) * out[s:done] + fade * part[: done - s]
        out[done:e] = part[done - s:]
        done = e
    if len(spans) > 1:
        out = rigidify(out, skeleton)  # the cross-fade mixes two fits: one skeleton again
    out = out.astype(np.float32)
    features = process_joints(out).features
    return EditedMotion(out, np.concatenate([features, features[-1:]]).astype(np.float32),
                        float(np.linalg.norm(out - joints, axis=-1).mean()))
