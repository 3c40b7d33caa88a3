"""HumanML3D-style ``.npy`` motion arrays: joints (T, 22, 3) or features (T, 263)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from simdiff.errors import MotionFormatError, SimdiffError
from simdiff.motion.skeleton import NUM_JOINTS

FEATURE_DIM: int = 263
"""Width of a HumanML3D feature vector (``new_joint_vecs``)."""


def save_npy(path: str | Path, joints: np.ndarray) -> Path:
    """Save (T, 22, 3) joint positions (metres, Y-up) as float32 ``.npy``.

    Raises:
        SimdiffError: when ``joints`` is not a finite (T, 22, 3) array.
    """
    array = np.asarray(joints, dtype=np.float32)
    if array.ndim != 3 or array.shape[1:] != (NUM_JOINTS, 3):
        raise SimdiffError(f"save_npy needs joints of shape (T, 22, 3), got {array.shape}")
    if not np.all(np.isfinite(array)):
        raise SimdiffError("save_npy: joints contain NaN or infinite values")
    from simdiff.fsio import save_npy as atomic_save_npy

    return atomic_save_npy(Path(path), array)


def read_npy(path: str | Path) -> np.ndarray:
    """Load a ``.npy`` motion: (T, 22, 3) joints or (T, 263) features, float32.

    Raises:
        MotionFormatError: for an unreadable file or any other shape.
    """
    path = Path(path)
    try:
        array = np.load(path, allow_pickle=False)
    except (OSError, ValueError) as exc:
        raise MotionFormatError(path, f"cannot read .npy array ({exc})") from None
    if array.ndim == 3 and array.shape[1:] == (NUM_JOINTS, 3):
        pass
    elif array.ndim == 2 and array.shape[1] == FEATURE_DIM:
        pass
    else:
        raise MotionFormatError(
            path, f"expected (T, 22, 3) joints or (T, {FEATURE_DIM}) features, got {array.shape}"
        )
    if array.shape[0] == 0:
        raise MotionFormatError(path, "empty motion (0 frames)")
    if not np.issubdtype(array.dtype, np.number) or not np.all(np.isfinite(array)):
        raise MotionFormatError(path, "array has non-finite or non-numeric values")
    return array.astype(np.float32)
