"""`RigMotion`: joint positions of any source rig, as read from a motion file."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from simdiff.errors import MotionFormatError


@dataclass
class RigMotion:
    """Global joint positions of one motion on its own rig.

    Attributes:
        names: joint names, length J.
        parents: parent index of every joint (-1 for the root), length J; a parent always
            comes before its children.
        positions: (T, J, 3) float32 global joint positions in metres, Y-up.
        fps: frames per second of ``positions``.
        source: the file the motion was read from (None when built in memory).
        meta: reader-specific extras (e.g. the BVH scale used), never needed downstream.
    """

    names: tuple[str, ...]
    parents: tuple[int, ...]
    positions: np.ndarray
    fps: float
    source: Path | None = None
    meta: dict[str, object] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self.names = tuple(self.names)
        self.parents = tuple(int(p) for p in self.parents)
        self.positions = np.asarray(self.positions, dtype=np.float32)
        if self.positions.ndim != 3 or self.positions.shape[1:] != (len(self.names), 3):
            raise ValueError(
                f"positions must be (T, {len(self.names)}, 3), got {self.positions.shape}"
            )
        if len(self.parents) != len(self.names):
            raise ValueError("names and parents differ in length")
        for j, p in enumerate(self.parents):
            if p >= j:
                raise ValueError(f"joint {self.names[j]!r} has parent index {p} >= its own {j}")
        self.fps = float(self.fps)

    @property
    def num_frames(self) -> int:
        """Number of frames T."""
        return int(self.positions.shape[0])

    def index(self, name: str) -> int:
        """Index of the joint called ``name`` (KeyError when absent)."""
        try:
            return self.names.index(name)
        except ValueError:
            raise KeyError(name) from None

    def joint(self, name: str) -> np.ndarray:
        """(T, 3) positions of one joint, metres."""
        return self.positions[:, self.index(name)]


def read_motion_text(path: Path, kind: str) -> str:
    """The text of a motion file; an unreadable file raises a one-line ``MotionFormatError``.

    Args:
        path: the file.
        kind: format name for the message, e.g. ``"BVH"``.
    """
    try:
        return path.read_text(encoding="utf-8", errors="replace")
    except OSError as exc:
        raise MotionFormatError(path, f"cannot read {kind} file ({exc.strerror})") from None
