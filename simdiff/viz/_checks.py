"""Input checks shared by the renderers; bad input raises :class:`SimdiffError`."""

from __future__ import annotations

from pathlib import Path
from typing import Sequence

import numpy as np

from simdiff.errors import SimdiffError
from simdiff.motion.skeleton import NUM_JOINTS

ANIMATION_SUFFIXES: tuple[str, ...] = (".gif", ".mp4")
IMAGE_SUFFIXES: tuple[str, ...] = (".png", ".jpg", ".jpeg", ".pdf", ".svg")


def as_motions(motions: object) -> list[np.ndarray]:
    """Validate motions and return them as a list of (T, 22, 3) float32 arrays.

    Accepts a sequence of array-likes (numpy arrays, CPU tensors) or one (T, 22, 3) array.
    """
    if isinstance(motions, np.ndarray) or hasattr(motions, "detach"):
        motions = [motions]
    if not isinstance(motions, Sequence) or isinstance(motions, (str, bytes)):
        raise SimdiffError(f"motions must be a list of (T, 22, 3) arrays, got {type(motions).__name__}")
    if len(motions) == 0:
        raise SimdiffError("motions is an empty list; give at least one (T, 22, 3) array")
    out = []
    for i, motion in enumerate(motions):
        if hasattr(motion, "detach"):
            motion = motion.detach().cpu().numpy()
        try:
            arr = np.asarray(motion, dtype=np.float32)
        except (TypeError, ValueError) as exc:
            raise SimdiffError(f"motion {i} is not numeric: {exc}") from None
        if arr.ndim != 3 or arr.shape[1:] != (NUM_JOINTS, 3) or arr.shape[0] < 1:
            raise SimdiffError(f"motion {i} has shape {tuple(arr.shape)}, expected (T, {NUM_JOINTS}, 3) with T >= 1")
        if not np.isfinite(arr).all():
            raise SimdiffError(f"motion {i} contains NaN or infinite values")
        out.append(arr)
    return out


def as_captions(captions: Sequence[str] | None, n: int) -> list[str]:
    """One caption per motion (empty strings when ``captions`` is None)."""
    if captions is None:
        return [""] * n
    if isinstance(captions, str):
        captions = [captions]
    captions = list(captions)
    if len(captions) != n:
        raise SimdiffError(f"got {len(captions)} captions for {n} motions; give one per motion")
    return [str(c) for c in captions]


def output_path(path: str | Path, allowed: tuple[str, ...]) -> Path:
    """Check the suffix of ``path`` against ``allowed``, create its parent folder and probe that it is writable."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in allowed:
        raise SimdiffError(f"unsupported output suffix {suffix or '(none)'!r} in {str(path)!r}; use one of {', '.join(allowed)}")
    from simdiff.fsio import check_writable

    return check_writable(path)


def positive_int(value: object, name: str) -> int:
    """``value`` as an int >= 1."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
        raise SimdiffError(f"{name} must be a positive integer, got {value!r}")
    return int(value)


def positive_float(value: object, name: str) -> float:
    """``value`` as a finite float > 0."""
    try:
        out = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise SimdiffError(f"{name} must be a positive number, got {value!r}") from None
    if not np.isfinite(out) or out <= 0:
        raise SimdiffError(f"{name} must be a positive number, got {value!r}")
    return out
