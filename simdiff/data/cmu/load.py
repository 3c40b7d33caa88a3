"""Read one source file of a trial and retarget it to HumanML3D joints at 20 fps."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from simdiff.data.cmu.sources import Trial
from simdiff.errors import SimdiffError
from simdiff.motion.io.rig import RigMotion
from simdiff.motion.skeleton import FPS

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


GROUND_PERCENTILE: float = 5.0
"""Percentile of the per-frame lowest joint taken as the ground in :func:`lift_penetrations`."""
MAX_LIFT: float = 0.06
"""Largest vertical correction (m) of :func:`lift_penetrations`; deeper dips are left alone."""


def lift_penetrations(joints: np.ndarray, fps: float = FPS) -> np.ndarray:
    """Raise the frames that sink below the ground, then put the trial on the floor.

    The DeepMimic retargets were made without ground contact: in 1-5 % of the frames a toe
    (push-off with a rigid box foot) or a limb (rolls, get-ups) dips 2-10 cm below the level
    the body otherwise stands or lies on. The corpus floor is the lowest joint of a clip, so
    those few frames lifted the floor under all the others (median floating 79 mm vs 21 mm
    for AMC). Here the ground is the :data:`GROUND_PERCENTILE` th percentile of the per-frame
    lowest joint; a frame below it is raised by the missing height (at most
    :data:`MAX_LIFT`), the correction smoothed over 0.25 s so that no jerk is added.

    Args:
        joints: (T, 22, 3) metres, Y-up.
    Returns:
        (T, 22, 3) float32, floor (lowest joint) at y = 0.
    """
    from scipy.ndimage import maximum_filter1d, uniform_filter1d

    out = np.array(joints, dtype=np.float64, copy=True)
    lowest = out[..., 1].min(axis=-1)
    if lowest.size < 3:
        return out.astype(np.float32)
    ground = float(np.percentile(lowest, GROUND_PERCENTILE))
    lift = np.clip(ground - lowest, 0.0, MAX_LIFT)
    size = max(1, int(round(0.25 * fps)))
    lift = uniform_filter1d(maximum_filter1d(lift, size, mode="nearest"), size, mode="nearest")
    out[..., 1] += lift[:, None]
    out[..., 1] -= out[..., 1].min()
    return out.astype(np.float32)


def load_source(trial: Trial, rig: str) -> tuple[np.ndarray, int]:
    """(T, 22, 3) float32 joints of ``trial`` read from its ``rig`` file (metres, Y-up,
    20 fps, floor at y = 0, source bone proportions) and the number of leading source
    frames dropped (see :func:`read_source_rig`).

    Raises:
        SimdiffError: (often MotionFormatError) naming the file when it cannot be read.
    """
    from simdiff.motion.io import retarget_rig

    motion, skipped = read_source_rig(trial, rig)
    joints = retarget_rig(motion, fps=FPS)
    if rig == "deepmimic":
        joints = lift_penetrations(joints)
    if joints.ndim != 3 or joints.shape[1:] != (22, 3) or not np.all(np.isfinite(joints)):
        raise SimdiffError(f"{Path(trial.files[rig])}: retarget gave unusable joints {joints.shape}")
    return joints.astype(np.float32), skipped


def load_rig_joints(trial: Trial, rig: str) -> np.ndarray:
    """(T, 22, 3) float32 joints of ``trial`` read from its ``rig`` file: metres, Y-up, 20 fps.

    The floor (lowest joint of the trial) is at y = 0; bones keep the source proportions
    (the feature pipeline retargets them to the canonical skeleton). A BVH's first frame is
    dropped only when it is an added T-pose.

    Raises:
        SimdiffError: (often MotionFormatError) naming the file when it cannot be read.
    """
    return load_source(trial, rig)[0]
