"""AMC motion-data parsing: per-bone (T, ndof) channel values on an ASF skeleton."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from simdiff.errors import MotionFormatError
from simdiff.motion.io.asf import AsfSkeleton, _floats
from simdiff.motion.io.rig import read_motion_text


def _frame_number(token: str) -> bool:
    """Whether ``token`` is a frame number: ASCII digits, at most 9 of them."""
    return token.isascii() and token.isdecimal() and len(token) <= 9


def _dof_counts(skeleton: AsfSkeleton) -> dict[str, int]:
    ndof = {name: len(b.dofs) for name, b in skeleton.bones.items()}
    ndof["root"] = len(skeleton.root_order)
    return ndof


def parse_amc(path: Path, skeleton: AsfSkeleton) -> tuple[dict[str, np.ndarray], bool]:
    """Per-bone (T, ndof) AMC values and whether angles are degrees.

    A vectorised pass handles the usual regular file (same bone order every frame); any
    irregularity falls back to the line-by-line parser, which names the offending line.
    """
    text = read_motion_text(path, "AMC")
    fast = _parse_amc_regular(text, skeleton)
    return fast if fast is not None else _parse_amc_lines(path, text, skeleton)


def _parse_amc_regular(
    text: str, skeleton: AsfSkeleton
) -> tuple[dict[str, np.ndarray], bool] | None:
    """Vectorised parse of a regular AMC file, or None when anything looks off."""
    ndof = _dof_counts(skeleton)
    expected = {name for name, n in ndof.items() if n > 0}
    lines = text.splitlines()
    degrees = skeleton.degrees
    start = -1
    for i, raw in enumerate(lines):
        stripped = raw.strip()
        if not stripped:
            continue
        if stripped[0] in "#:":
            if stripped.upper() == ":RADIANS":
                degrees = False
            elif stripped.upper() == ":DEGREES":
                degrees = True
            continue
        start = i
        break
    if start < 0 or not _frame_number(lines[start].strip()):
        return None
    layout: list[tuple[str, int]] = []
    for raw in lines[start + 1 :]:
        words = raw.split()
        if not words:
            continue
        if len(words) == 1 and _frame_number(words[0]):
            break
        layout.append((words[0], len(words) - 1))
    if {name for name, _ in layout} != expected or len(layout) != len(expected):
        return None
    if any(ndof.get(name) != count for name, count in layout):
        return None
    per_frame = 1 + sum(1 + count for _, count in layout)
    tokens = "\n".join(lines[start:]).split()
    if len(tokens) % per_frame:
        return None
    table = np.array(tokens, dtype=object).reshape(-1, per_frame)
    first = int(lines[start].strip())
    numbers = np.arange(first, first + table.shape[0]).astype(str).astype(object)
    if not np.all(table[:, 0] == numbers):
        return None
    out: dict[str, np.ndarray] = {}
    col = 1
    for name, count in layout:
        if not np.all(table[:, col] == name):
            return None
        try:
            values = table[:, col + 1 : col + 1 + count].astype(np.float64)
        except ValueError:
            return None
        if not np.all(np.isfinite(values)):
            return None
        out[name] = values
        col += 1 + count
    return out, degrees


def _parse_amc_lines(
    path: Path, text: str, skeleton: AsfSkeleton
) -> tuple[dict[str, np.ndarray], bool]:
    """Line-by-line AMC parse that reports the first bad line."""
    ndof = _dof_counts(skeleton)
    expected = {name for name, n in ndof.items() if n > 0}
    values: dict[str, list[list[str]]] = {name: [] for name in expected}
    value_lines: dict[str, list[int]] = {name: [] for name in expected}
    degrees = skeleton.degrees
    frame_count = 0
    frame_line = 0
    seen: set[str] = set()
    last_line = 0

    def close_frame() -> None:
        if frame_count and seen != expected:
            lacking = sorted(expected - seen)
            raise MotionFormatError(
                path,
                f"frame {frame_number} lacks {len(lacking)} bone(s): {', '.join(lacking[:4])}",
                frame_line,
            )

    frame_number = 0
    for lineno, raw in enumerate(text.splitlines(), start=1):
        tokens = raw.split()
        if not tokens:
            continue
        last_line = lineno
        first = tokens[0]
        if first.startswith("#"):
            continue
        if first.startswith(":"):
            if frame_count:
                raise MotionFormatError(path, f"header keyword {first!r} after frame data", lineno)
            if first.upper() == ":RADIANS":
                degrees = False
            elif first.upper() == ":DEGREES":
                degrees = True
            continue
        if len(tokens) == 1 and _frame_number(first):
            close_frame()
            number = int(first)
            if frame_count and number != frame_number + 1:
                raise MotionFormatError(
                    path, f"frame number {number} does not follow {frame_number}", lineno
                )
            frame_number = number
            frame_count += 1
            frame_line = lineno
            seen = set()
            continue
        if not frame_count:
            raise MotionFormatError(path, f"expected a frame number, got {raw.strip()[:40]!r}", lineno)
        if first not in ndof:
            raise MotionFormatError(path, f"unknown bone {first!r}", lineno)
        if first in seen:
            raise MotionFormatError(path, f"bone {first!r} twice in frame {frame_number}", lineno)
        if len(tokens) - 1 != ndof[first]:
            raise MotionFormatError(
                path,
                f"bone {first!r} has {len(tokens) - 1} values, its ASF dofs need {ndof[first]}",
                lineno,
            )
        seen.add(first)
        values[first].append(tokens[1:])
        value_lines[first].append(lineno)
    if not frame_count:
        raise MotionFormatError(path, "no frames", last_line or None)
    close_frame()
    out: dict[str, np.ndarray] = {}
    for name, rows in values.items():
        try:
            array = np.array(rows, dtype=np.float64)
        except ValueError:
            for row, lineno in zip(rows, value_lines[name]):
                _floats(row, path, lineno, f"value for bone {name!r}")
            raise MotionFormatError(path, f"non-numeric value for bone {name!r}") from None
        if not np.all(np.isfinite(array)):
            bad = int(np.argwhere(~np.isfinite(array))[0, 0])
            raise MotionFormatError(
                path, f"non-finite value for bone {name!r}", value_lines[name][bad]
            )
        out[name] = array
    return out, degrees
