"""Read one source file of a trial and retarget it to HumanML3D joints at 20 fps.

``lift_penetrations`` (DeepMimic ground clean-up) lives in :mod:`simdiff.motion.io.ground`;
:func:`simdiff.motion.io.retarget_rig` applies it to DeepMimic rigs.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from simdiff.data.corpus.cmu_sources import Trial
from simdiff.errors import SimdiffError
from simdiff.motion.io.rig import RigMotion
from simdiff.motion.skeleton import FPS

__all__ = ["BVH_FPS", "load_source", "read_source_rig", "source_fps", "source_frame"]

BVH_FPS: float = 60.0
"""Frame rate of the Character-Creator CMU BVH set."""


def source_fps(trial: Trial, rig: str) -> float:
    """Frame rate of the trial's ``rig`` file (frames per second)."""
    return {"amc": trial.capture_fps, "bvh": BVH_FPS, "deepmimic": 30.0}[rig]


def source_frame(trial: Trial, rig: str, frame20: int, skipped: int = 0) -> int:
    """Frame number in the source file of 20 fps frame ``frame20`` (0-based), where the
    first ``skipped`` source frames were dropped (a BVH's added T-pose)."""
    return int(round(frame20 * source_fps(trial, rig) / FPS)) + skipped


def read_source_rig(trial: Trial, rig: str) -> tuple[RigMotion, int]:
    """The trial's ``rig`` file on its own rig, and how many leading frames were dropped.

    A BVH's frame 0 is dropped only when it is an added T-pose
    (:func:`simdiff.motion.io.bvh.starts_with_tpose`: 10 of the 61 CMU BVH files, 07_03-07_12).

    Raises:
        SimdiffError: (often MotionFormatError) naming the file when it cannot be read.
    """
    from simdiff.motion.io import load_rig
    from simdiff.motion.io.bvh import starts_with_tpose

    path = trial.files.get(rig)
    if path is None:
        raise SimdiffError(f"trial {trial.trial} has no {rig} file")
    if rig == "amc":
        if trial.asf is None:
            raise SimdiffError(f"{path}: no ASF skeleton for subject {trial.subject}")
        return load_rig(path, asf=trial.asf, fps=trial.capture_fps), 0
    if rig == "bvh":
        motion = load_rig(path, drop_first=False)
        if starts_with_tpose(motion.positions):
            motion = RigMotion(motion.names, motion.parents, motion.positions[1:], motion.fps,
                               motion.source, motion.meta)
            return motion, 1
        return motion, 0
    if rig == "deepmimic":
        return load_rig(path), 0
    raise SimdiffError(f"unknown rig kind {rig!r}")


def load_source(trial: Trial, rig: str) -> tuple[np.ndarray, int]:
    """(T, 22, 3) float32 joints of ``trial`` read from its ``rig`` file (metres, Y-up,
    20 fps, floor at y = 0, source bone proportions) and the number of leading source
    frames dropped (see :func:`read_source_rig`).

    Raises:
        SimdiffError: (often MotionFormatError) naming the file when it cannot be read.
    """
    from simdiff.motion.io import retarget_rig

    motion, skipped = read_source_rig(trial, rig)
    joints = retarget_rig(motion, fps=FPS)  # DeepMimic: includes lift_penetrations
    if joints.ndim != 3 or joints.shape[1:] != (22, 3) or not np.all(np.isfinite(joints)):
        raise SimdiffError(f"{Path(trial.files[rig])}: retarget gave unusable joints {joints.shape}")
    return joints.astype(np.float32), skipped
