"""Helpers for the reader tests: tiny BVH texts built from a joint list, and single members
of the real ``../shared/data/extra`` archives extracted to a temporary folder."""

from __future__ import annotations

import tarfile
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np
import pytest

Joint = tuple[str, str | None, tuple[float, float, float], Sequence[str]]
"""(name, parent name or None for the root, OFFSET, channel names)."""


def bvh_text(joints: Sequence[Joint], frames: np.ndarray, frame_time: float,
             end_sites: dict[str, tuple[float, float, float]] | None = None) -> str:
    """A BVH file: ``joints`` in depth-first order (parents first), ``frames`` (T, C) channel
    values in that order, optional End Sites by joint name."""
    end_sites = end_sites or {}
    children: dict[str | None, list[Joint]] = {}
    for joint in joints:
        children.setdefault(joint[1], []).append(joint)
    lines = ["HIERARCHY"]

    def emit(joint: Joint, depth: int) -> None:
        name, parent, offset, channels = joint
        pad = "  " * depth
        lines.append(f"{pad}{'ROOT' if parent is None else 'JOINT'} {name}")
        lines.append(f"{pad}{{")
        lines.append(f"{pad}  OFFSET {offset[0]} {offset[1]} {offset[2]}")
        if channels:
            lines.append(f"{pad}  CHANNELS {len(channels)} {' '.join(channels)}")
        for child in children.get(name, []):
            emit(child, depth + 1)
        if name in end_sites:
            e = end_sites[name]
            lines.extend([f"{pad}  End Site", f"{pad}  {{", f"{pad}    OFFSET {e[0]} {e[1]} {e[2]}", f"{pad}  }}"])
        lines.append(f"{pad}}}")

    emit(children[None][0], 0)
    lines += ["MOTION", f"Frames: {len(frames)}", f"Frame Time: {frame_time}"]
    lines += [" ".join(f"{v:.6f}" for v in row) for row in np.atleast_2d(frames)]
    return "\n".join(lines) + "\n"


ROT = ("Zrotation", "Xrotation", "Yrotation")
POS_ROT = ("Xposition", "Yposition", "Zposition", *ROT)


def channel_count(joints: Sequence[Joint]) -> int:
    """Total number of channels."""
    return sum(len(j[3]) for j in joints)


def extra_member(shared_data: Path, archive: str, tmp_path: Path,
                 want: Callable[[str], bool], companion: Callable[[str], str] | None = None) -> Path:
    """Extract the first member of ``extra/<archive>`` whose name satisfies ``want`` into
    ``tmp_path`` (and, with ``companion``, the member named ``companion(first_name)``, which
    may come later in the archive); skip the test when the archive is absent."""
    path = shared_data / "extra" / archive
    if not path.is_file():
        pytest.skip(f"{path} is absent")
    found: str | None = None
    need: str | None = None
    with tarfile.open(path, "r:*") as tar:
        for member in tar:
            if not member.isfile():
                continue
            if found is None and want(member.name):
                tar.extract(member, tmp_path, filter="data")
                found = member.name
                need = companion(found) if companion else None
                if need is None:
                    break
            elif need is not None and member.name == need:
                tar.extract(member, tmp_path, filter="data")
                break
    if found is None:
        pytest.skip(f"no matching member in {path}")
    return tmp_path / found
