"""JSON shape of a motion sent to the page: joints, frame rate, skeleton, metadata."""

from __future__ import annotations

from typing import Any

import numpy as np

from simdiff.errors import SimdiffError
from simdiff.motion.skeleton import (
    FPS,
    JOINT_NAMES,
    KINEMATIC_CHAIN,
    NUM_JOINTS,
    PARENTS,
)

DECIMALS: int = 4
"""Joint coordinates are rounded to 0.1 mm to keep responses small."""


def skeleton_info() -> dict[str, Any]:
    """The HumanML3D 22-joint skeleton: ``parents``, ``chain`` (5 limbs), joint ``names``."""
    return {"parents": list(PARENTS), "chain": [list(c) for c in KINEMATIC_CHAIN], "names": list(JOINT_NAMES)}


def motion_payload(joints: np.ndarray, meta: dict[str, Any]) -> dict[str, Any]:
    """Build ``{joints, fps, parents, meta}`` for one motion.

    Args:
        joints: (T, 22, 3) positions in metres, Y-up, 20 fps.
        meta: JSON-able description (source, prompt, φ, ...); ``frames`` and ``seconds`` are added.
    Raises:
        SimdiffError: wrong shape or non-finite values (JSON cannot carry NaN).
    """
    arr = np.asarray(joints, dtype=np.float32)
    if arr.ndim != 3 or arr.shape[1:] != (NUM_JOINTS, 3) or arr.shape[0] < 1:
        raise SimdiffError(f"expected joints of shape (T, 22, 3), got {tuple(arr.shape)}")
    if not np.all(np.isfinite(arr)):
        raise SimdiffError("the motion contains NaN or infinite coordinates")
    frames = int(arr.shape[0])
    return {
        "joints": np.round(arr.astype(np.float64), DECIMALS).tolist(),
        "fps": FPS,
        "parents": list(PARENTS),
        "meta": {**meta, "frames": frames, "seconds": round(frames / FPS, 3)},
    }
