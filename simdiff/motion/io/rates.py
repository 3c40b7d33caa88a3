"""Frame rates: the checked range every rate must fall in, and hints that override a wrong BVH header.

Every frame rate a reader takes from a file (a BVH ``Frame Time``, a DeepMimic frame duration, a
``CMU_data.csv`` row, a folder ``readme.txt``) or from a caller (an ``fps`` override, :func:`resample`)
passes :func:`check_fps`: a finite number in [:data:`MIN_FPS`, :data:`MAX_FPS`] Hz, else a one-line error.

The acLSTM dance folders (``aclstm/{salsa,martial,indian}/NN.bvh``) come with a
``readme.txt`` giving each folder's capture rate ("salsa  framerate 60"). Every header
says 120 fps, but the salsa takes are CMU subjects 60/61, which ``CMU_data.csv`` lists at
60 fps, and at 120 fps each foot would step 2.0-2.4 times a second (a 330 bpm salsa); at
60 fps it is 1.0-1.2 (about 170 bpm). The readme is therefore trusted over the header.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

from simdiff.errors import MotionFormatError, SimdiffError
from simdiff.limits import MAX_FPS, MIN_FPS

__all__ = ["MAX_FPS", "MIN_FPS", "FrameRateError", "check_fps", "folder_fps_hint", "fps_problem"]


class FrameRateError(SimdiffError, ValueError):
    """A frame rate that is not a finite number in [:data:`MIN_FPS`, :data:`MAX_FPS`] Hz (also a ``ValueError``)."""


def fps_problem(fps: object) -> str | None:
    """Why ``fps`` is not a usable frame rate (one short phrase), or None when it is."""
    try:
        value = float(fps)  # type: ignore[arg-type]
    except (TypeError, ValueError, OverflowError):
        return f"is not a number ({fps!r})"
    if not math.isfinite(value):
        return f"is not a finite number ({value})"
    if value <= 0:
        return f"must be positive, got {value:g}"
    if value < MIN_FPS:
        return f"{value:g} Hz is below {MIN_FPS:g} Hz"
    if value > MAX_FPS:
        return f"{value:g} Hz is above {MAX_FPS:g} Hz"
    return None


def check_fps(fps: object, what: str = "frame rate", path: object = None, line: int | None = None) -> float:
    """``fps`` as a float when it is a finite number in [:data:`MIN_FPS`, :data:`MAX_FPS`] Hz.

    Args:
        fps: the rate, Hz.
        what: what the rate is, for the message (e.g. ``"fps"``, ``"Frame Time"``).
        path, line: the file (and line) it came from: the error is then a :class:`MotionFormatError`.
    Raises:
        FrameRateError: (no ``path``) or MotionFormatError (``path``): one line naming the value.
    """
    problem = fps_problem(fps)
    if problem is None:
        return float(fps)  # type: ignore[arg-type]
    message = f"{what} {problem} (frame rates must lie in [{MIN_FPS:g}, {MAX_FPS:g}] Hz)"
    if path is not None:
        raise MotionFormatError(path, message, line)
    raise FrameRateError(message)


_RATE_LINE = re.compile(r"^\s*(\S+)\s+frame\s*rate\s*[:=]?\s*([0-9]+(?:\.[0-9]+)?)\s*$", re.IGNORECASE)


def folder_fps_hint(path: str | Path) -> float | None:
    """Frame rate of ``path``'s folder stated in a ``readme.txt`` one level up, or None.

    The readme line must read ``<folder name> framerate <fps>`` (case-insensitive, any
    spacing, optional ``:``); e.g. ``salsa  framerate 60`` for ``salsa/01.bvh``.

    Raises:
        MotionFormatError: the readme states a rate outside [:data:`MIN_FPS`, :data:`MAX_FPS`] Hz for this folder.
    """
    path = Path(path)
    folder = path.parent.name
    for name in ("readme.txt", "README.txt", "README.TXT"):
        readme = path.parent.parent / name
        if not readme.is_file():
            continue
        try:
            lines = readme.read_text(encoding="utf-8", errors="replace").splitlines()
        except OSError:
            return None
        for lineno, line in enumerate(lines, start=1):
            match = _RATE_LINE.match(line)
            if match and match.group(1) == folder:
                return check_fps(float(match.group(2)), f"frame rate of {folder}/", readme, lineno)
        return None
    return None
