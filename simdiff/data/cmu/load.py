"""Read one source file of a trial and retarget it to HumanML3D joints at 20 fps."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from simdiff.data.cmu.sources import Trial
from simdiff.errors import SimdiffError
from simdiff.motion.skeleton import FPS

BVH_FPS: float = 60.0
"""Frame rate of the Character-Creator CMU BVH set (frame 0, an added T-pose, is dropped)."""


def source_fps(trial: Trial, rig: str) -> float:
    """Frame rate of the trial's ``rig`` file (frames per second)."""
    return {"amc": trial.capture_fps, "bvh": BVH_FPS, "deepmimic": 30.0}[rig]


def source_frame(trial: Trial, rig: str, frame20: int) -> int:
    """Frame number in the source file of 20 fps frame ``frame20`` (0-based; BVH counts its T-pose)."""
    frame = int(round(frame20 * source_fps(trial, rig) / FPS))
    return frame + 1 if rig == "bvh" else frame


def load_rig_joints(trial: Trial, rig: str) -> np.ndarray:
    """(T, 22, 3) float32 joints of ``trial`` read from its ``rig`` file: metres, Y-up, 20 fps.

    The floor (lowest joint of the trial) is at y = 0; bones keep the source proportions
    (the feature pipeline retargets them to the canonical skeleton).

    Raises:
        SimdiffError: (often MotionFormatError) naming the file when it cannot be read.
    """
    from simdiff.motion.io import load_joints

    path = trial.files.get(rig)
    if path is None:
        raise SimdiffError(f"trial {trial.trial} has no {rig} file")
    if rig == "amc":
        if trial.asf is None:
            raise SimdiffError(f"{path}: no ASF skeleton for subject {trial.subject}")
        joints = load_joints(path, asf=trial.asf, fps=trial.capture_fps)
    elif rig == "bvh":
        joints = load_joints(path, drop_first=True)
    elif rig == "deepmimic":
        joints = load_joints(path)
    else:
        raise SimdiffError(f"unknown rig kind {rig!r}")
    if joints.ndim != 3 or joints.shape[1:] != (22, 3) or not np.all(np.isfinite(joints)):
        raise SimdiffError(f"{Path(path)}: retarget gave unusable joints {joints.shape}")
    return joints.astype(np.float32)
