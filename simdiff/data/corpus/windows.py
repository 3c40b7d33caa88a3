"""Cut a trial (20 fps joint frames) into clips of 2–9.8 s.

A clip of ``n`` joint frames gives ``n - 1`` feature rows, so windows hold 41..197 joint
frames (40..196 feature rows: MDM keeps 40 <= len < 200 and pads to 196).
HumanML3D's own segment bounds are used where the trial has them (cut to 9.8 s; segments
under 2 s are ignored); stretches of at least 2 s that no segment covers are cut into equal
windows, shorter leftovers (often the still start or end of a take) are dropped. Trials
without segments are cut into equal windows; a whole trial under 2 s gives none.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from simdiff.data.corpus.cmu_sources import Segment

MAX_WINDOW: int = 197
"""Most joint frames in a clip (196 feature rows, 9.8 s)."""
MIN_WINDOW: int = 41
"""Fewest joint frames in a clip (40 feature rows, 2 s)."""


@dataclass(frozen=True)
class Window:
    """Joint frames [start, stop) of a trial at 20 fps; ``origin`` is "hml3d:<id>" or "even"."""

    start: int
    stop: int
    origin: str

    @property
    def frames(self) -> int:
        """Joint frames in the window."""
        return self.stop - self.start


def _fit(start: int, stop: int, total: int, min_len: int, max_len: int) -> tuple[int, int] | None:
    """Clamp [start, stop) into [0, total) and cut it to ``max_len`` frames; None if under ``min_len``."""
    start, stop = max(0, start), min(total, stop)
    if stop - start > max_len:
        stop = start + max_len
    if stop - start < min_len:
        return None
    return start, stop


def even_windows(start: int, stop: int, max_len: int = MAX_WINDOW) -> list[tuple[int, int]]:
    """Cut [start, stop) into the fewest equal windows of at most ``max_len`` frames."""
    length = stop - start
    if length <= 0:
        return []
    count = max(1, math.ceil(length / max_len))
    edges = [start + round(i * length / count) for i in range(count + 1)]
    return [(a, b) for a, b in zip(edges[:-1], edges[1:])]


def plan_windows(
    num_frames: int,
    segments: Sequence[Segment] = (),
    *,
    min_len: int = MIN_WINDOW,
    max_len: int = MAX_WINDOW,
) -> list[Window]:
    """Windows of a trial with ``num_frames`` joint frames at 20 fps.

    Args:
        num_frames: frames of the retargeted trial.
        segments: HumanML3D segments (frames at 20 fps; they may overlap).
        min_len, max_len: window bounds in joint frames.
    Returns:
        Windows sorted by start; empty when the trial is shorter than ``min_len``.
    """
    out: list[Window] = []
    seen: set[tuple[int, int]] = set()
    covered = [False] * num_frames
    for seg in sorted(segments, key=lambda s: (s.start20, s.end20, s.hml_id)):
        if seg.start20 >= num_frames - 1:
            continue
        fitted = _fit(seg.start20, seg.end20, num_frames, min_len, max_len)
        if fitted is None or fitted in seen:
            continue
        seen.add(fitted)
        out.append(Window(fitted[0], fitted[1], f"hml3d:{seg.hml_id}"))
        for t in range(fitted[0], fitted[1]):
            covered[t] = True
    # runs of uncovered frames, cut into equal windows when long enough
    t = 0
    while t < num_frames:
        if covered[t]:
            t += 1
            continue
        run_start = t
        while t < num_frames and not covered[t]:
            t += 1
        if t - run_start < min_len:
            continue
        for a, b in even_windows(run_start, t, max_len):
            fitted = _fit(a, b, num_frames, min_len, max_len)
            if fitted is not None and fitted not in seen:
                seen.add(fitted)
                out.append(Window(fitted[0], fitted[1], "even"))
    return sorted(out, key=lambda w: (w.start, w.stop))
