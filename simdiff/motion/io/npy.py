"""HumanML3D-style ``.npy`` motion arrays: joints (T, 22, 3) or features (T, 263)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from simdiff.errors import MotionFormatError, SimdiffError
from simdiff.limits import MAX_COORD
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


MAX_FRAMES: int = 10_000_000
"""Most frames a ``.npy`` motion may declare (over five days at 20 fps)."""


def _check_header(path: Path) -> None:
    """Refuse a file that is not a NumPy array file, holds Python objects, or declares more data than it has."""
    try:
        with open(path, "rb") as handle:
            try:
                version = np.lib.format.read_magic(handle)
            except ValueError:
                raise MotionFormatError(path, "not a NumPy .npy array file") from None
            try:
                if version == (1, 0):
                    shape, _, dtype = np.lib.format.read_array_header_1_0(handle)
                else:
                    shape, _, dtype = np.lib.format.read_array_header_2_0(handle)
            except (ValueError, SyntaxError, TypeError):
                raise MotionFormatError(path, "not a NumPy .npy array file (bad header)") from None
            offset = handle.tell()
        size = path.stat().st_size
    except OSError as exc:
        raise MotionFormatError(path, f"cannot read .npy file ({exc.strerror})") from None
    if dtype.hasobject:
        raise MotionFormatError(path, "the array holds Python objects, not numbers")
    if dtype.kind not in "biuf" or dtype.fields is not None:
        raise MotionFormatError(path, f"the array holds {dtype.name} values, not real numbers")
    if int(np.prod(shape, dtype=object)) * dtype.itemsize > size - offset:
        raise MotionFormatError(path, f"truncated: the header declares shape {shape}, the file holds less data")


def read_npy(path: str | Path) -> np.ndarray:
    """Load a ``.npy`` motion: (T, 22, 3) joints or (T, 263) features, float32.

    The header is checked before any data is read: a file that is not a NumPy array, an array
    of Python objects or of non-real numbers, a shape larger than the file, more than
    :data:`MAX_FRAMES` frames, non-finite values and values beyond ±:data:`~simdiff.limits.MAX_COORD`
    (:func:`check_coordinates`) are each refused in one line.

    Raises:
        MotionFormatError: for an unreadable file or any other shape.
    """
    path = Path(path)
    _check_header(path)
    try:
        array = np.load(path, mmap_mode="r", allow_pickle=False)
    except (OSError, ValueError) as exc:
        raise MotionFormatError(path, f"cannot read .npy array ({str(exc).splitlines()[0][:120]})") from None
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
    if array.shape[0] > MAX_FRAMES:
        raise MotionFormatError(path, f"{array.shape[0]} frames, more than {MAX_FRAMES}")
    with np.errstate(over="ignore", invalid="ignore"):  # values beyond float32 become inf, refused below
        array = np.array(array, dtype=np.float32)
    if not np.all(np.isfinite(array)):
        raise MotionFormatError(path, "array has non-finite values")
    check_coordinates(path, array, "values" if array.ndim == 2 else "coordinates")
    return array


def check_coordinates(path: str | Path, array: np.ndarray, what: str = "coordinates") -> None:
    """Refuse a motion whose values reach beyond ±:data:`~simdiff.limits.MAX_COORD` (10 km in metres).

    Raises:
        MotionFormatError: one line naming ``path`` and the largest value.
    """
    if array.size == 0:
        return
    with np.errstate(invalid="ignore"):
        peak = float(np.max(np.abs(array)))
    if not peak <= MAX_COORD:
        raise MotionFormatError(path, f"{what} reach {peak:.3g}, beyond ±{MAX_COORD:g} m "
                                      f"(not a body moving in metres)")
