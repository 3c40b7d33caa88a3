"""DeepMimic motion reader (JSON ``{"Loop": ..., "Frames": [[...], ...]}``, humanoid3d).

A frame holds 44 numbers: duration dt (s), root position (3, metres, Y-up), root rotation
(w, x, y, z), then the local rotations of chest, neck, right hip, right knee, right ankle,
right shoulder, right elbow, left hip, left knee, left ankle, left shoulder, left elbow:
spherical joints as quaternions (w, x, y, z), revolute ones (knees, elbows) as one angle
in radians about the joint's local Z axis. The wrists are fixed.

The humanoid3d character (DeepMimic ``data/characters/humanoid3d.txt``) faces +X with its
right side towards +Z; its joint attachment offsets in the parent frame, metres, are in
:data:`HUMANOID3D`. Positions are found by FK: a joint lies at
``parent_pos + parent_rot @ attach``; its rotation is ``parent_rot @ local_rot``.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from simdiff.errors import MotionFormatError
from simdiff.motion.io.rates import check_fps
from simdiff.motion.io.rig import RigMotion, read_motion_text
from simdiff.motion.quaternion import qnormalize, quat_to_matrix

HUMANOID3D: tuple[tuple[str, int, str, tuple[float, float, float]], ...] = (
    ("root", -1, "none", (0.0, 0.0, 0.0)),
    ("chest", 0, "spherical", (0.0, 0.236151, 0.0)),
    ("neck", 1, "spherical", (0.0, 0.223894, 0.0)),
    ("right_hip", 0, "spherical", (0.0, 0.0, 0.084887)),
    ("right_knee", 3, "revolute", (0.0, -0.421546, 0.0)),
    ("right_ankle", 4, "spherical", (0.0, -0.409870, 0.0)),
    ("right_shoulder", 1, "spherical", (-0.02405, 0.24350, 0.18311)),
    ("right_elbow", 6, "revolute", (0.0, -0.274788, 0.0)),
    ("right_wrist", 7, "fixed", (0.0, -0.258947, 0.0)),
    ("left_hip", 0, "spherical", (0.0, 0.0, -0.084887)),
    ("left_knee", 9, "revolute", (0.0, -0.421546, 0.0)),
    ("left_ankle", 10, "spherical", (0.0, -0.409870, 0.0)),
    ("left_shoulder", 1, "spherical", (-0.02405, 0.24350, -0.18311)),
    ("left_elbow", 12, "revolute", (0.0, -0.274788, 0.0)),
    ("left_wrist", 13, "fixed", (0.0, -0.258947, 0.0)),
)
"""(name, parent index, joint type, attach offset in metres) of the 15 humanoid3d links."""

SITES: tuple[tuple[str, str, tuple[float, float, float]], ...] = (
    ("right_toe", "right_ankle", (0.12, -0.045, 0.0)),
    ("left_toe", "left_ankle", (0.12, -0.045, 0.0)),
    ("neck_top", "neck", (0.0, 0.06, 0.0)),
    ("head", "neck", (0.0, 0.16, 0.0)),
)
"""Derived points (not in the character file), (name, link, offset in the link frame):
the ball of the foot near the front-bottom of the 0.177 m foot box; the upper neck and the
head centre (the neck joint sits at shoulder height, the head sphere 0.175 m above it)."""

_DOFS = {"none": 0, "spherical": 4, "revolute": 1, "fixed": 0}
VALUES_PER_FRAME: int = 1 + 3 + 4 + sum(_DOFS[j[2]] for j in HUMANOID3D[1:])
"""44: dt, root position, root quaternion, then the joint rotations."""

DEFAULT_FPS: float = 30.0


def _frame_lines(text: str) -> list[int]:
    """1-based line of the opening bracket of every frame inside "Frames"."""
    lines: list[int] = []
    line, depth, in_string, escaped = 1, 0, False, False
    frames_depth = -1
    last_key = ""
    key_start = -1
    for pos, char in enumerate(text):
        if char == "\n":
            line += 1
        if in_string:
            if escaped:
                escaped = False
            elif char == "\\":
                escaped = True
            elif char == '"':
                in_string = False
                last_key = text[key_start + 1 : pos]
            continue
        if char == '"':
            in_string, key_start = True, pos
        elif char in "[{":
            depth += 1
            if char == "[" and frames_depth < 0 and last_key == "Frames" and depth == 2:
                frames_depth = depth
            elif char == "[" and frames_depth > 0 and depth == frames_depth + 1:
                lines.append(line)
        elif char in "]}":
            if depth == frames_depth:
                frames_depth = -2  # done
            depth -= 1
    return lines


@np.errstate(over="ignore", invalid="ignore")
def read_deepmimic(path: str | Path, *, fps: float | None = None) -> RigMotion:
    """Read a DeepMimic humanoid3d motion file into global joint positions.

    Args:
        path: the JSON motion (``.txt`` or ``.json``).
        fps: frame rate; default 1 / median frame duration (30 for the CMU set). Frames
            with other durations are put on this rate's grid by their time stamps.
    Returns:
        RigMotion with the 15 humanoid3d links plus :data:`SITES` (right_toe, left_toe,
        neck_top, head): (T, 19, 3) metres, Y-up (the character faces +X at identity root rotation).
    Raises:
        MotionFormatError: naming the file and line of a malformed or truncated input.
    """
    path = Path(path)
    text = read_motion_text(path, "DeepMimic")
    try:
        doc = json.loads(text)
    except json.JSONDecodeError as exc:
        raise MotionFormatError(path, f"invalid JSON: {exc.msg}", exc.lineno) from None
    except RecursionError:
        raise MotionFormatError(path, "invalid DeepMimic JSON: nested too deeply") from None
    except ValueError:  # an integer of thousands of digits
        raise MotionFormatError(path, "invalid JSON: a number thousands of digits long") from None
    if not isinstance(doc, dict) or "Frames" not in doc:
        raise MotionFormatError(path, "not a DeepMimic motion: no \"Frames\" list", 1)
    frames = doc["Frames"]
    if not isinstance(frames, list) or not frames:
        raise MotionFormatError(path, "\"Frames\" must be a non-empty list", _key_line(text, "Frames"))
    for k, frame in enumerate(frames):
        ok = isinstance(frame, list) and len(frame) == VALUES_PER_FRAME
        ok = ok and all(isinstance(v, (int, float)) and not isinstance(v, bool) and abs(v) < 1e300 for v in frame)
        if not ok or not np.all(np.isfinite(np.asarray(frame, dtype=np.float64))):
            line = _nth(_frame_lines(text), k)
            what = (
                f"has {len(frame)} values, expected {VALUES_PER_FRAME}"
                if isinstance(frame, list) and len(frame) != VALUES_PER_FRAME
                else "is not a list of finite numbers"
            )
            raise MotionFormatError(path, f"frame {k} {what}", line)
    data = np.asarray(frames, dtype=np.float64)
    dts = data[:, 0]
    if np.any(dts < 0):
        k = int(np.argmax(dts < 0))
        raise MotionFormatError(path, f"frame {k} has a negative duration", _nth(_frame_lines(text), k))
    if fps is None:
        positive = dts[dts > 0]
        if positive.size == 0:
            fps = DEFAULT_FPS
        else:
            fps = check_fps(1.0 / float(np.median(positive)), "the frame rate of the frame durations", path)
    else:
        fps = check_fps(fps, "fps")
    quats = [data[:, 4:8]]
    col = 8
    angles: dict[int, np.ndarray] = {}
    for j, (_, _, kind, _) in enumerate(HUMANOID3D[1:], start=1):
        if kind == "spherical":
            quats.append(data[:, col : col + 4])
            col += 4
        elif kind == "revolute":
            angles[j] = data[:, col]
            col += 1
    norms = [np.linalg.norm(q, axis=-1) for q in quats]
    for q_norm in norms:
        if np.any(q_norm < 1e-6):
            k = int(np.argmax(q_norm < 1e-6))
            raise MotionFormatError(path, f"frame {k} has a zero quaternion", _nth(_frame_lines(text), k))
    positions, rotations = _forward_kinematics(data, quats, angles)
    names = [j[0] for j in HUMANOID3D] + [s[0] for s in SITES]
    parents = [j[1] for j in HUMANOID3D] + [names.index(s[1]) for s in SITES]
    extra = []
    for _, link, offset in SITES:
        i = names.index(link)
        extra.append(positions[:, i] + rotations[:, i] @ np.asarray(offset))
    all_positions = np.concatenate([positions, np.stack(extra, axis=1)], axis=1)
    if float(np.sum(dts[:-1])) * fps > 10 * len(dts) + 100:  # resampling would make far more frames than given
        raise MotionFormatError(path, f"frame durations add up to {float(np.sum(dts[:-1])):g} s, far more than "
                                      f"{len(dts)} frames at {fps:g} fps")
    all_positions, retimed = _uniform_time(all_positions, dts, fps)
    all_positions = all_positions.astype(np.float32)
    if not np.all(np.isfinite(all_positions)):
        raise MotionFormatError(path, "joint positions overflow: root position values too large")
    return RigMotion(
        names=tuple(names),
        parents=tuple(parents),
        positions=all_positions,
        fps=fps,
        source=path,
        meta={"loop": doc.get("Loop"), "retimed": retimed},
    )


def _uniform_time(positions: np.ndarray, dts: np.ndarray, fps: float) -> tuple[np.ndarray, bool]:
    """Positions on a uniform ``fps`` grid when the frame durations vary.

    A frame's ``dt`` is the time to the next frame (the last one is usually 0). When every
    duration but the last is within 5 % of 1 / ``fps`` the frames are kept as they are;
    otherwise (e.g. ``humanoid3d_roll``: one 0.033 s gap among 0.0167 s frames) the
    positions are linearly interpolated at ``k / fps`` on the cumulative time stamps.

    Returns:
        (T', J, 3) positions and whether they were resampled.
    """
    steps = dts[:-1]
    if len(steps) == 0 or np.all(np.abs(steps * fps - 1.0) <= 0.05):
        return positions, False
    times = np.concatenate([[0.0], np.cumsum(steps)])
    grid = np.arange(0.0, times[-1] + 0.5 / fps, 1.0 / fps)
    grid = grid[grid <= times[-1] + 1e-9]
    flat = positions.reshape(len(positions), -1)
    out = np.stack([np.interp(grid, times, flat[:, c]) for c in range(flat.shape[1])], axis=1)
    return out.reshape(len(grid), *positions.shape[1:]), True


def _forward_kinematics(
    data: np.ndarray, quats: list[np.ndarray], angles: dict[int, np.ndarray]
) -> tuple[np.ndarray, np.ndarray]:
    """(T, 15, 3) positions and (T, 15, 3, 3) global rotations of the humanoid3d links."""
    num_frames = data.shape[0]
    spherical = iter(quats[1:])
    positions = np.empty((num_frames, len(HUMANOID3D), 3))
    rotations = np.empty((num_frames, len(HUMANOID3D), 3, 3))
    positions[:, 0] = data[:, 1:4]
    rotations[:, 0] = quat_to_matrix(qnormalize(quats[0]))
    for j, (_, parent, kind, attach) in enumerate(HUMANOID3D[1:], start=1):
        if kind == "spherical":
            local = quat_to_matrix(qnormalize(next(spherical)))
        elif kind == "revolute":
            theta = angles[j]
            c, s = np.cos(theta), np.sin(theta)
            local = np.zeros((num_frames, 3, 3))
            local[:, 0, 0], local[:, 0, 1] = c, -s
            local[:, 1, 0], local[:, 1, 1] = s, c
            local[:, 2, 2] = 1.0
        else:
            local = np.broadcast_to(np.eye(3), (num_frames, 3, 3))
        rotations[:, j] = rotations[:, parent] @ local
        positions[:, j] = positions[:, parent] + rotations[:, parent] @ np.asarray(attach)
    return positions, rotations


def _nth(lines: list[int], k: int) -> int | None:
    return lines[k] if k < len(lines) else None


def _key_line(text: str, key: str) -> int | None:
    pos = text.find(f'"{key}"')
    return text.count("\n", 0, pos) + 1 if pos >= 0 else None
