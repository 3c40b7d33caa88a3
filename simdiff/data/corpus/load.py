"""Read one :class:`~.item.Item` as HumanML3D joints (T, 22, 3), metres, Y-up, 20 fps,
floor at y = 0, source bone proportions."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from simdiff.data.corpus.item import Item
from simdiff.errors import SimdiffError

_CMU_RIG = {"cmu-amc": "amc", "cmu-bvh": "bvh", "cmu-deepmimic": "deepmimic"}
_DEFAULT_FPS = {"bandai": 30.0, "deepmimic": 30.0, "cmu-deepmimic": 30.0, "cmu-bvh": 60.0}


def bvh_frame_rate(path: Path) -> float | None:
    """Frames per second from a BVH's ``Frame Time:`` line (None when absent)."""
    with open(path, "rb") as handle:
        for raw in handle:
            line = raw.decode("latin-1").strip()
            if line.lower().startswith("frame time:"):
                try:
                    dt = float(line.split(":", 1)[1])
                except ValueError:
                    return None
                return round(1.0 / dt, 3) if dt > 0 else None
    return None


def source_fps(item: Item) -> float | None:
    """The source file's frame rate (forced rate, AMC rate, BVH header or the source's known rate)."""
    if item.fps is not None:
        return float(item.fps)
    trial = item.meta.get("cmu_trial")
    if item.source == "cmu-amc" and trial is not None:
        return float(trial.capture_fps)  # type: ignore[attr-defined]
    if item.path.suffix.lower() == ".bvh":
        return bvh_frame_rate(item.path)
    return _DEFAULT_FPS.get(item.source)


def _check(item: Item, joints: np.ndarray) -> np.ndarray:
    if joints.ndim != 3 or joints.shape[1:] != (22, 3) or not np.all(np.isfinite(joints)):
        raise SimdiffError(f"{item.path}: retarget gave unusable joints {joints.shape}")
    return np.ascontiguousarray(joints, dtype=np.float32)


def load_item(item: Item) -> tuple[np.ndarray, int]:
    """(T, 22, 3) float32 joints of ``item`` at 20 fps and the leading source frames dropped.

    CMU copies in ``shared/cmu`` go through :func:`simdiff.data.corpus.cmu_load.load_source`; the rest through
    :func:`simdiff.motion.io.load_joints` (which knows the Bandai, Motionbuilder, Daz, HDM05 and DeepMimic rigs and their clean-ups).

    Raises:
        SimdiffError: (often MotionFormatError) naming the file.
    """
    from simdiff.data.corpus.cmu_load import load_source
    from simdiff.motion.io import load_joints

    if item.source in _CMU_RIG and "cmu_trial" in item.meta:
        joints, skipped = load_source(item.meta["cmu_trial"], _CMU_RIG[item.source])  # type: ignore[arg-type]
        return _check(item, joints), skipped
    if item.source == "hdm05":
        return _check(item, load_joints(item.path, asf=item.asf, fps=item.fps)), 0
    if item.source == "bandai":
        return _check(item, load_joints(item.path, drop_first=False)), 0
    return _check(item, load_joints(item.path, asf=item.asf, fps=item.fps)), 0
