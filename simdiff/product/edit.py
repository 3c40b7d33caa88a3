"""A user's motion re-played under φ, in the user's own frame and skeleton (``simdiff edit``)."""

from __future__ import annotations

import shutil
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from simdiff.diffusion.config import SamplingConfig
from simdiff.errors import SimdiffError
from simdiff.motion.skeleton import FPS, NUM_JOINTS
from simdiff.product.outputs import (
    prepare_out_dir,
    render_video,
    write_metadata,
    write_motion,
)

if TYPE_CHECKING:
    from simdiff.inference.generator import MotionGenerator
    from simdiff.sim.env import Environment

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
    """``joints`` as float64 (T, 22, 3), T ≥ :data:`MIN_EDIT_FRAMES`, finite; one-line errors otherwise."""
    joints = np.asarray(joints, dtype=np.float64)
    if joints.ndim != 3 or joints.shape[1:] != (NUM_JOINTS, 3):
        raise SimdiffError(f"{name} must be (T, 22, 3) joints, got shape {joints.shape}")
    if joints.shape[0] < MIN_EDIT_FRAMES:
        raise SimdiffError(f"{name} has {joints.shape[0]} frames; editing needs at least {MIN_EDIT_FRAMES} (0.5 s)")
    if not np.all(np.isfinite(joints)):
        raise SimdiffError(f"{name} contains NaN or infinite values")
    return joints


def edit_motion(generator: MotionGenerator, joints: np.ndarray, config: SamplingConfig, env: Sequence[float], *,
                seed: int = 0, text: str = "") -> EditedMotion:
    """Re-play ``joints`` (T, 22, 3) metres, Y up, 20 fps under φ = ``env`` (g_z m/s², w_x N, w_y N).

    The model's answer to φ (:func:`simdiff.inference.replay.replay_features`, canonical frame, HumanML3D skeleton)
    is turned back into the input's frame and scale and added to its joints (smoothed like every written motion,
    :func:`simdiff.motion.rigid.smooth_positions`); the sum is fitted with rotations on the input's own skeleton
    and, where φ changed something, its planted feet are held by leg IK at ``config.foot_lock``. At Earth without
    wind the input comes back (rigidly fitted).
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
    replay = replay_features(generator, features, config, env, seed=seed, text=text)
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
              half: str, text: str, *, seed: int = 0) -> EditedMotion:
    """``joints`` (T ≤ 196, 22, 3) with one half of the body (``half`` in :data:`HALVES`) kept, every frame, and the
    other made anew for ``text`` under φ = ``env`` (None: a backbone-only model): the kept joints are keyframes
    (:func:`simdiff.inference.keyframes.sample_keyframed`) and the result is fitted on the input's skeleton."""
    from simdiff.inference.keyframes import sample_keyframed
    from simdiff.motion.rigid import rest_offsets
    from simdiff.motion.skeleton import LOWER_BODY, MAX_FRAMES, UPPER_BODY

    if half not in HALVES:
        raise SimdiffError(f"--keep must be one of {', '.join(HALVES)}, got {half!r}")
    joints = check_motion(joints)
    if joints.shape[0] > MAX_FRAMES:
        raise SimdiffError(f"the motion has {joints.shape[0]} frames; --keep takes up to {MAX_FRAMES} (9.8 s)")
    keys = np.full_like(joints, np.nan)
    kept = list(LOWER_BODY if half == "lower" else UPPER_BODY)
    keys[:, kept] = joints[:, kept]
    features, out = sample_keyframed(generator, keys, config, text_embeddings=generator.encode_text([text]),
                                     env=None if env is None else tuple(env), seed=seed, skeleton=rest_offsets(joints))
    return EditedMotion(out, features, float(np.linalg.norm(out - joints, axis=-1).mean()))


@dataclass(frozen=True)
class EditRequest:
    """One checked ``simdiff edit`` run.

    Attributes:
        source: the motion file; joints: its (T, 22, 3) joints, metres, Y up, 20 fps.
        env: φ to re-play under (or to make the new half under).
        formats: output kinds (:data:`simdiff.product.request.FORMATS`).
        text: what the motion shows (optional for a re-play; the new half's prompt with ``keep``).
        seed: noise seed.
        keep: None (re-play under φ) or the half kept (:data:`HALVES`).
    """

    source: Path
    joints: np.ndarray
    env: Environment
    formats: Sequence[str]
    text: str = ""
    seed: int = 0
    keep: str | None = None


def edit_file(request: EditRequest, out_dir: Path, *, model: Path | None = None,
              device: str = "cpu") -> tuple[list[Path], str]:
    """Run ``request`` with the default (or given) model and write the edit, a side-by-side video and ``edit.json``
    into ``out_dir``; (written paths, a one-line summary). A failed run leaves no folder it created behind."""
    from simdiff.inference.default import check_model_dir

    folder = check_model_dir(model)
    created = not out_dir.exists()
    try:
        return _edit_into(request, prepare_out_dir(out_dir), folder, model, device)
    except BaseException:
        if created:
            shutil.rmtree(out_dir, ignore_errors=True)
        raise


def _edit_into(request: EditRequest, out_dir: Path, folder: Path, model: Path | None,
               device: str) -> tuple[list[Path], str]:
    """:func:`edit_file` once the output folder exists."""
    import time

    from simdiff.fsio import check_writable, output_set
    from simdiff.inference.default import load_default, sampling_config
    from simdiff.inference.device import torch_device
    from simdiff.motion.gravity_readout import read_gravity
    from simdiff.product.pipeline import describe_env

    check_writable(out_dir / "edit.json")  # a read-only folder fails now, not after sampling
    start = time.perf_counter()
    joints, env = request.joints, request.env
    generator = load_default(model, torch_device(device), load_text=bool(request.text))
    continuous = generator.config.sim is not None and generator.config.sim.mode == "continuous"
    if request.keep is None and not continuous:
        raise SimdiffError(f"{folder} has no continuous environment input (φ as numbers); it cannot re-play a "
                           "motion under gravity and wind")
    if request.keep is not None and generator.is_simdiff and not continuous:
        raise SimdiffError(f"{folder} has categorical environments; use a model with φ as numbers")
    config = sampling_config(model)
    loaded = time.perf_counter()
    if request.keep is None:
        edited = edit_motion(generator, joints, config, env.as_tuple(), seed=request.seed, text=request.text)
    else:
        edited = keep_half(generator, joints, config, env.as_tuple() if generator.is_simdiff else None, request.keep,
                           request.text, seed=request.seed)
    sampled = time.perf_counter()
    before, after = read_gravity(joints), read_gravity(edited.joints)
    label = describe_env(env) if request.keep is None else f"{request.keep} body kept: {request.text}"
    with output_set(out_dir, last="edit.json") as stage:  # every file appears together, or none
        written = write_motion(stage / "edited", edited.joints, edited.features, request.formats)
        paths = list(written.values())
        for kind in ("gif", "mp4"):
            if kind in request.formats:
                paths.append(render_video([joints.astype(np.float32), edited.joints], ["input", label],
                                          stage / f"compare.{kind}"))
        meta = {
            "input": str(request.source), "frames": int(joints.shape[0]), "fps": FPS,
            "environment": {"gravity": env.gravity, "wind": [env.wind_x, env.wind_y]},
            "keep": request.keep, "text": request.text, "seed": request.seed, "sampling": config.to_dict(),
            "model": str(folder), "changed_m": round(edited.changed_m, 4),
            "gravity_read": {"input": before, "edited": after},
            "files": sorted(p.name for p in paths),
            "seconds": {"load_model": round(loaded - start, 3), "sample": round(sampled - loaded, 3),
                        "write": round(time.perf_counter() - sampled, 3)},
        }
        paths.append(write_metadata(stage / "edit.json", meta))
    paths = [out_dir / p.name for p in paths]
    what = "re-played under " + describe_env(env) if request.keep is None else f"with the {request.keep} body kept"
    return paths, f"{joints.shape[0]} frames {what}; joints moved {100 * edited.changed_m:.1f} cm on average"
