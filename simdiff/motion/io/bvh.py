"""Generic BVH (Biovision hierarchy) reader: any channel order, 3- or 6-channel joints.

Conventions (as Blender's importer): rotation channels compose in the order listed,
outermost first (``Zrotation Xrotation Yrotation`` -> Rz @ Rx @ Ry); a joint with position
channels takes them as its local translation in place of its OFFSET (for the root: the
global position); a child lies at ``parent + G_parent @ offset``. ``End Site`` points are
kept as joints named ``<parent>_End``. File units are converted to metres by ``scale``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from simdiff.errors import MotionFormatError
from simdiff.motion.io.euler import euler_to_matrix
from simdiff.motion.io.rates import MAX_FPS, MIN_FPS, check_fps, fps_problem
from simdiff.motion.io.rig import RigMotion, read_motion_text

_CHANNELS = ("xposition", "yposition", "zposition", "xrotation", "yrotation", "zrotation")

KNOWN_SCALES: dict[str, float] = {
    "m": 1.0, "cm": 0.01, "mm": 0.001, "inch": 0.0254, "cmu": 0.0254 / 0.45,
}
"""Unit -> metres factors considered by :func:`detect_scale` (``cmu``: the CMU ASF length
unit, inch / 0.45, kept by the CMU Motionbuilder BVH conversion)."""

HUMAN_HEIGHT: float = 1.7
"""Typical standing height in metres, the target of :func:`detect_scale`."""


@dataclass
class BvhJoint:
    """One BVH joint (or End Site): offset in file units, channel names lower-cased."""

    name: str
    parent: int
    offset: np.ndarray
    channels: tuple[str, ...] = ()
    line: int = 0
    is_end: bool = False


@dataclass
class BvhFile:
    """A parsed BVH: joints in file order (parents first) and raw (T, C) channel values."""

    path: Path
    joints: list[BvhJoint]
    frame_time: float
    values: np.ndarray
    channel_start: list[int] = field(default_factory=list)


class _Tokens:
    """Whitespace tokens of the hierarchy part with their 1-based line numbers."""

    def __init__(self, path: Path, lines: list[str]) -> None:
        self.path = path
        self.items: list[tuple[str, int]] = []
        self.motion_line = 0
        for lineno, raw in enumerate(lines, start=1):
            words = raw.split()
            if words and words[0].upper() == "MOTION":
                self.motion_line = lineno
                break
            self.items.extend((w, lineno) for w in words)
        self.pos = 0
        self.last_line = len(lines)

    def next(self, what: str) -> tuple[str, int]:
        if self.pos >= len(self.items):
            line = self.motion_line or self.last_line
            raise MotionFormatError(self.path, f"hierarchy ends early: expected {what}", line or None)
        item = self.items[self.pos]
        self.pos += 1
        return item

    def peek(self) -> tuple[str, int] | None:
        return self.items[self.pos] if self.pos < len(self.items) else None

    def expect(self, word: str) -> int:
        token, line = self.next(repr(word))
        if token.upper() != word.upper():
            raise MotionFormatError(self.path, f"expected {word!r}, got {token[:40]!r}", line)
        return line

    def number(self, what: str) -> float:
        token, line = self.next(what)
        try:
            value = float(token)
        except ValueError:
            raise MotionFormatError(self.path, f"expected a number for {what}, got {token[:40]!r}", line) from None
        if not np.isfinite(value):
            raise MotionFormatError(self.path, f"non-finite {what}", line)
        return value


MAX_DEPTH: int = 256
"""Deepest joint nesting a BVH hierarchy may have (a human rig is about 10 deep)."""
MAX_JOINTS: int = 4096
"""Most joints a BVH hierarchy may have (a human rig with fingers has about 100)."""


def _parse_hierarchy(tokens: _Tokens, root_name: str, root_line: int) -> list[BvhJoint]:
    """Parse the root's ``{ OFFSET .. CHANNELS .. children }`` and every joint below it, iteratively."""
    path = tokens.path
    joints: list[BvhJoint] = []
    open_joints: list[int] = []  # indices of the joints whose '}' is still to come
    pending: tuple[str, int] | None = (root_name, root_line)
    while pending is not None or open_joints:
        if pending is not None:  # a joint's keyword and name are read: its block follows
            name, line = pending
            pending = None
            if len(open_joints) >= MAX_DEPTH:
                raise MotionFormatError(path, f"hierarchy deeper than {MAX_DEPTH} joints", line)
            if len(joints) >= MAX_JOINTS or len(name) > 200:
                what = f"more than {MAX_JOINTS} joints" if len(name) <= 200 else "a joint name over 200 characters"
                raise MotionFormatError(path, f"hierarchy has {what}", line)
            open_joints.append(_joint_head(tokens, joints, open_joints[-1] if open_joints else -1, name, line))
            continue
        index = open_joints[-1]
        name = joints[index].name
        token, tline = tokens.next("'}' or a child joint")
        upper = token.upper()
        if upper == "}":
            open_joints.pop()
        elif upper == "JOINT":
            pending = tokens.next("joint name")
        elif upper == "END":
            tokens.expect("Site")
            tokens.expect("{")
            tokens.expect("OFFSET")
            end_offset = np.array([tokens.number(f"End Site OFFSET of {name!r}") for _ in range(3)])
            tokens.expect("}")
            joints.append(
                BvhJoint(name=f"{name}_End", parent=index, offset=end_offset, line=tline, is_end=True)
            )
        else:
            raise MotionFormatError(path, f"unexpected {token[:40]!r} in joint {name!r}", tline)
    return joints


def _joint_head(tokens: _Tokens, joints: list[BvhJoint], parent: int, name: str, line: int) -> int:
    """Read ``{ OFFSET x y z [CHANNELS n ...]`` of one joint, append it; returns its index."""
    path = tokens.path
    tokens.expect("{")
    tokens.expect("OFFSET")
    offset = np.array([tokens.number(f"OFFSET of {name!r}") for _ in range(3)])
    joint = BvhJoint(name=name, parent=parent, offset=offset, line=line)
    joints.append(joint)
    peek = tokens.peek()
    if peek is not None and peek[0].upper() == "CHANNELS":
        tokens.next("CHANNELS")
        count_token, count_line = tokens.next("channel count")
        if not (count_token.isdecimal() and int(count_token[:4]) <= len(_CHANNELS)):
            raise MotionFormatError(path, f"bad channel count {count_token[:20]!r} (0 to 6)", count_line)
        channels = []
        for _ in range(int(count_token)):
            channel, ch_line = tokens.next("channel name")
            if channel.lower() not in _CHANNELS:
                raise MotionFormatError(path, f"unknown channel {channel[:40]!r}", ch_line)
            channels.append(channel.lower())
        if len(set(channels)) != len(channels):
            raise MotionFormatError(path, f"repeated channel in {name!r}", count_line)
        joint.channels = tuple(channels)
    return len(joints) - 1


def parse_bvh(path: str | Path) -> BvhFile:
    """Parse a BVH file into its hierarchy and raw channel values (file units, degrees).

    Raises:
        MotionFormatError: naming the file and line of the first problem.
    """
    path = Path(path)
    text = read_motion_text(path, "BVH")
    lines = text.splitlines()
    tokens = _Tokens(path, lines)
    first = tokens.peek()
    if first is None or first[0].upper() != "HIERARCHY":
        line = first[1] if first else 1
        raise MotionFormatError(path, "not a BVH file: it must start with HIERARCHY", line)
    tokens.next("HIERARCHY")
    tokens.expect("ROOT")
    root_name, root_line = tokens.next("root name")
    joints = _parse_hierarchy(tokens, root_name, root_line)
    extra = tokens.peek()
    if extra is not None:
        raise MotionFormatError(
            path, f"unexpected {extra[0][:40]!r} after the root joint (one skeleton only)", extra[1]
        )
    if not tokens.motion_line:
        raise MotionFormatError(path, "no MOTION section", len(lines) or None)
    names = [j.name for j in joints]
    if len(set(names)) != len(names):
        seen: set[str] = set()
        dup = next(n for n in names if n in seen or seen.add(n))  # type: ignore[func-returns-value]
        raise MotionFormatError(path, f"duplicate joint name {dup!r}", joints[names.index(dup)].line)

    row = tokens.motion_line  # 0-based index of the line after MOTION
    num_frames, row = _header_value(path, lines, row, "Frames:")
    frames_row = row
    frame_time, row = _header_value(path, lines, row, "Frame Time:")
    if not (math.isfinite(num_frames) and num_frames >= 0 and num_frames == int(num_frames)):
        raise MotionFormatError(path, f"Frames must be a whole number, got {num_frames:g}", frames_row)
    if not (frame_time > 0 and fps_problem(1.0 / frame_time) is None):  # nan, inf, <= 0, outside MIN..MAX_FPS Hz
        raise MotionFormatError(path, f"Frame Time must be seconds per frame, {1 / MAX_FPS:g} to {1 / MIN_FPS:g} "
                                      f"({MIN_FPS:g} to {MAX_FPS:g} frames per second), got {frame_time:g}", row)
    n = int(num_frames)
    starts, total = [], 0
    for joint in joints:
        starts.append(total)
        total += len(joint.channels)
    data_lines: list[str] = []
    data_numbers: list[int] = []
    for offset_row, raw in enumerate(lines[row:], start=row + 1):
        if raw.strip():
            data_lines.append(raw)
            data_numbers.append(offset_row)
    if len(data_lines) < n:
        raise MotionFormatError(
            path, f"truncated: Frames says {n} but {len(data_lines)} frame lines follow", len(lines)
        )
    if len(data_lines) > n:
        raise MotionFormatError(path, f"more frame lines than Frames: {n}", data_numbers[n])
    values = np.empty((n, total), dtype=np.float64)
    for k, (raw, lineno) in enumerate(zip(data_lines, data_numbers)):
        words = raw.split()
        if len(words) != total:
            raise MotionFormatError(
                path, f"frame {k + 1} has {len(words)} values, the hierarchy has {total} channels", lineno
            )
        try:
            values[k] = [float(w) for w in words]
        except ValueError:
            bad = next(w for w in words if not _is_float(w))
            raise MotionFormatError(path, f"non-numeric value {bad[:40]!r} in frame {k + 1}", lineno) from None
    if not np.all(np.isfinite(values)):
        k = int(np.argwhere(~np.isfinite(values))[0, 0])
        raise MotionFormatError(path, f"non-finite value in frame {k + 1}", data_numbers[k])
    return BvhFile(path=path, joints=joints, frame_time=frame_time, values=values, channel_start=starts)


def _is_float(word: str) -> bool:
    try:
        float(word)
    except ValueError:
        return False
    return True


def _header_value(path: Path, lines: list[str], row: int, key: str) -> tuple[float, int]:
    """Value after ``key`` on the next non-blank line at or after ``row`` (0-based)."""
    while row < len(lines) and not lines[row].strip():
        row += 1
    if row >= len(lines):
        raise MotionFormatError(path, f"file ends before '{key}'", len(lines) or None)
    raw = lines[row].strip()
    if not raw.lower().startswith(key.lower()):
        raise MotionFormatError(path, f"expected '{key}', got {raw[:40]!r}", row + 1)
    try:
        return float(raw[len(key):].strip()), row + 1
    except ValueError:
        raise MotionFormatError(path, f"bad number after '{key}'", row + 1) from None


def forward_kinematics(bvh: BvhFile, scale: float = 1.0) -> np.ndarray:
    """Global joint positions (T, J, 3) of a parsed BVH, in file axes times ``scale``."""
    return forward_kinematics_rotations(bvh, scale)[0]


def forward_kinematics_rotations(bvh: BvhFile, scale: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """Global positions (T, J, 3) (file axes x ``scale``) and rotations (T, J, 3, 3) of a BVH."""
    num_frames = bvh.values.shape[0]
    joints = bvh.joints
    rotations = np.empty((num_frames, len(joints), 3, 3))
    positions = np.empty((num_frames, len(joints), 3))
    for i, joint in enumerate(joints):
        start = bvh.channel_start[i]
        local_t = np.broadcast_to(joint.offset * scale, (num_frames, 3)).copy()
        rot_axes, rot_cols = [], []
        for k, channel in enumerate(joint.channels):
            if channel.endswith("position"):
                local_t[:, "xyz".index(channel[0])] = bvh.values[:, start + k] * scale
            else:
                rot_axes.append(channel[0].upper())
                rot_cols.append(start + k)
        local_r = euler_to_matrix(bvh.values[:, rot_cols], "".join(rot_axes))
        if joint.parent < 0:
            rotations[:, i] = local_r
            positions[:, i] = local_t
        else:
            parent_r = rotations[:, joint.parent]
            rotations[:, i] = parent_r @ local_r
            positions[:, i] = positions[:, joint.parent] + (parent_r @ local_t[..., None])[..., 0]
    return positions, rotations


def rig_height(positions: np.ndarray) -> float:
    """Rough body size: 90th percentile over frames of the largest joint-cloud extent
    (input units); a high percentile so that clips spent crouching or sitting still see
    the standing (or lying) body.

    Args:
        positions: (T, J, 3) joint positions.
    """
    extent = positions.max(axis=1) - positions.min(axis=1)
    return float(np.percentile(extent.max(axis=-1), 90))


def detect_scale(height: float) -> float:
    """Factor to metres among :data:`KNOWN_SCALES` that brings ``height`` nearest 1.7 m.

    Args:
        height: body size in file units (see :func:`rig_height`).
    """
    if not height > 0:
        return 1.0
    return min(KNOWN_SCALES.values(), key=lambda s: abs(np.log(height * s / HUMAN_HEIGHT)))


def starts_with_tpose(positions: np.ndarray) -> bool:
    """Whether frame 0 is an added rest pose: it jumps far (> 10 cm mean, > 10x the
    median frame-to-frame motion) from frame 1, as in the CMU Character-Creator BVH set.

    Args:
        positions: (T, J, 3) joint positions in metres.
    """
    if positions.shape[0] < 3:
        return False
    steps = np.linalg.norm(np.diff(positions, axis=0), axis=-1).mean(axis=-1)
    return bool(steps[0] > 0.10 and steps[0] > 10.0 * np.median(steps[1:]))


TRANSIENT_WINDOW: float = 0.1
"""Seconds at the start of a clip searched by :func:`leading_transient`."""
TRANSIENT_SPEED: float = 2.0
"""Metres per second: smallest median-joint speed of a frame step counted as a start-up jump
(a T-pose blend moves 20-40 m/s; real motion at a clip start well under 1 m/s)."""
TRANSIENT_FACTOR: float = 5.0
"""A start-up jump is also this many times the clip's median step."""


def leading_transient(positions: np.ndarray, fps: float) -> int:
    """Number of leading frames to drop: an added rest pose and the blend out of it.

    Several BVH conversions start with a T-pose, followed (Daz-style CMU files, the
    acLSTM dances) by 3-5 frames interpolated from it into the motion, or (CMU
    Motionbuilder 09_10) by frames left at the origin. Every frame before the last step
    within the first :data:`TRANSIENT_WINDOW` s (at least 2 steps) whose median joint
    displacement exceeds both :data:`TRANSIENT_SPEED` / ``fps`` and :data:`TRANSIENT_FACTOR` x the
    clip's median step is dropped, and so are the following frames while the step keeps
    shrinking and stays above twice the median step (the end of the blend).

    Args:
        positions: (T, J, 3) joint positions in metres.
        fps: frames per second.
    """
    if positions.shape[0] < 4:
        return 0
    steps = np.median(np.linalg.norm(np.diff(positions, axis=0), axis=-1), axis=-1)
    limit = max(TRANSIENT_SPEED / fps, TRANSIENT_FACTOR * float(np.median(steps)))
    window = min(len(steps) - 1, max(2, int(round(TRANSIENT_WINDOW * fps))))
    jumps = np.flatnonzero(steps[:window] > limit)
    if not jumps.size:
        return 0
    # the blend out of the rest pose: steps still shrinking and above 2x the median step
    end = int(jumps[-1])
    typical = 2.0 * float(np.median(steps))
    while end + 1 < len(steps) - 1 and typical < steps[end + 1] < steps[end]:
        end += 1
    return end + 1


def _to_y_up(positions: np.ndarray, up: str) -> np.ndarray:
    """Rotate positions whose up axis is ``up`` ("y", "z" or "-z"... ) so that up is +Y."""
    up = up.lower()
    if up == "y":
        return positions
    x, y, z = positions[..., 0], positions[..., 1], positions[..., 2]
    if up == "z":  # right-handed Z-up -> Y-up: rotate -90 degrees about X
        return np.stack([x, z, -y], axis=-1)
    if up == "x":  # right-handed X-up -> Y-up: rotate +90 degrees about Z
        return np.stack([-y, x, z], axis=-1)
    raise ValueError(f"up must be 'x', 'y' or 'z', got {up!r}")


def read_bvh(
    path: str | Path,
    *,
    scale: float | None = None,
    up: str = "y",
    drop_first: bool = False,
    fps: float | None = None,
    sites: Sequence[tuple[str, str, str, tuple[float, float, float]]] = (),
    rest_axes: Sequence[Sequence[float]] = ((1, 0, 0), (0, 1, 0), (0, 0, 1)),
) -> RigMotion:
    """Read a BVH file into global joint positions.

    Args:
        path: the ``.bvh`` file.
        scale: file units -> metres (0.01 for centimetres); None detects it from the size
            of the posed rig (:func:`detect_scale`: m, cm, mm, inches or CMU units).
        up: the file's up axis ("y", "z" or "x"); positions are rotated to Y-up.
        drop_first: skip frame 0 (e.g. an added T-pose, as in the CMU Character-Creator set).
        fps: frame rate; default 1 / Frame Time.
        sites: derived points ``(name, joint, child, (left, up, forward))`` appended as
            joints (see :data:`simdiff.motion.io.rigs.base.BvhSite`).
        rest_axes: (left, up, forward) of the rest pose in file axes, for ``sites``.
    Returns:
        RigMotion with every joint, End Site and site, (T, J, 3) metres Y-up; ``meta``
        holds "scale" and "frame_time".
    Raises:
        MotionFormatError: naming the file (and line) of a malformed, truncated or overflowing input.
    """
    return rig_from_bvh(parse_bvh(path), scale=scale, up=up, drop_first=drop_first, fps=fps,
                        sites=sites, rest_axes=rest_axes)


@np.errstate(over="ignore", invalid="ignore")
def rig_from_bvh(
    bvh: BvhFile,
    *,
    scale: float | None = None,
    up: str = "y",
    drop_first: bool = False,
    fps: float | None = None,
    sites: Sequence[tuple[str, str, str, tuple[float, float, float]]] = (),
    rest_axes: Sequence[Sequence[float]] = ((1, 0, 0), (0, 1, 0), (0, 0, 1)),
) -> RigMotion:
    """A parsed BVH as a :class:`RigMotion`; arguments as :func:`read_bvh`."""
    if drop_first:
        if bvh.values.shape[0] < 2:
            raise MotionFormatError(bvh.path, "cannot drop the first frame of a one-frame motion")
        bvh.values = bvh.values[1:]
    if bvh.values.shape[0] == 0:
        raise MotionFormatError(bvh.path, "no frames (Frames: 0)")
    if scale is None:
        step = max(1, len(bvh.values) // 16)
        sample = BvhFile(bvh.path, bvh.joints, bvh.frame_time, bvh.values[::step], bvh.channel_start)
        probe = forward_kinematics(sample)
        scale = detect_scale(rig_height(probe))
    elif not scale > 0:
        raise ValueError(f"scale must be positive, got {scale}")
    positions, rotations = forward_kinematics_rotations(bvh, scale)
    names = [j.name for j in bvh.joints]
    parents = [j.parent for j in bvh.joints]
    if sites:
        extra = _site_positions(bvh, names, positions, rotations, scale, sites, rest_axes)
        positions = np.concatenate([positions, extra], axis=1)
        names += [s[0] for s in sites]
        parents += [names.index(s[1]) for s in sites]
    positions = _to_y_up(positions, up).astype(np.float32)
    if not np.all(np.isfinite(positions)):  # overflowing values (warnings silenced by the decorator)
        raise MotionFormatError(bvh.path, "joint positions overflow: OFFSET or position values too large")
    return RigMotion(
        names=tuple(names),
        parents=tuple(parents),
        positions=positions,
        fps=check_fps(fps, "fps") if fps is not None else 1.0 / bvh.frame_time,
        source=bvh.path,
        meta={"scale": scale, "frame_time": bvh.frame_time},
    )


def rest_positions(bvh: BvhFile) -> np.ndarray:
    """(J, 3) joint positions of the rest pose (OFFSETs only, all rotations zero), file units."""
    out = np.zeros((len(bvh.joints), 3))
    for i, joint in enumerate(bvh.joints):
        out[i] = joint.offset + (out[joint.parent] if joint.parent >= 0 else 0.0)
    return out


def _site_positions(
    bvh: BvhFile, names: list[str], positions: np.ndarray, rotations: np.ndarray, scale: float,
    sites: Sequence[tuple[str, str, str, tuple[float, float, float]]],
    rest_axes: Sequence[Sequence[float]],
) -> np.ndarray:
    """(T, S, 3) positions of derived sites, rigid with their joint's global frame."""
    rest = rest_positions(bvh) * scale
    axes = np.asarray(rest_axes, dtype=np.float64)
    out = []
    for name, joint, child, offset in sites:
        if joint not in names or child not in names:
            raise MotionFormatError(bvh.path, f"site {name!r} needs joints {joint!r} and {child!r}")
        j, c = names.index(joint), names.index(child)
        bone = rest[c] - rest[j]
        parent = bvh.joints[j].parent
        own = rest[j] - rest[parent] if parent >= 0 else bone
        unit = float(np.linalg.norm(bone if c != j else own))
        local = bone + unit * (np.asarray(offset, dtype=np.float64) @ axes)
        out.append(positions[:, j] + rotations[:, j] @ local)
    return np.stack(out, axis=1)
