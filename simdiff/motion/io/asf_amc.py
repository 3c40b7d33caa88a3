"""Acclaim ASF skeleton + AMC motion reader (the CMU mocap format).

Units: ASF ``:units length L`` means a stored length ``v`` is ``v / L`` inches, so metres
are ``v / L * 0.0254`` (CMU: L = 0.45). The root translation in AMC uses the same unit.
Angles are degrees unless ``angle rad`` (ASF) or ``:RADIANS`` (AMC). CMU data is Y-up.

Rotation conventions (column vectors): a bone's local frame is ``C`` = its ``axis`` angles
applied in the stated order (``axis 0 0 20 XYZ`` -> Rz @ Ry @ Rx); its motion ``M`` is its
``dof`` angles applied in the listed order (``dof rx ry rz`` -> Rz @ Ry @ Rx). The global
rotation is ``G = G_parent @ C @ M @ C^-1`` and the bone's end lies at
``parent_end + G @ direction * length``.
"""

from __future__ import annotations

import csv
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from simdiff.errors import MotionFormatError
from simdiff.motion.io.euler import euler_to_matrix
from simdiff.motion.io.rig import RigMotion, read_motion_text

INCH: float = 0.0254
"""Metres per inch."""

DEFAULT_FPS: float = 120.0
"""Capture rate of most CMU trials (a few are 60 fps: see CMU_data.csv)."""

_ROT_DOFS = ("rx", "ry", "rz")
_ALL_DOFS = ("rx", "ry", "rz", "tx", "ty", "tz", "l")


@dataclass
class AsfBone:
    """One ASF bone: unit ``direction`` (3,) in the global rest frame, ``length`` metres."""

    name: str
    direction: np.ndarray
    length: float
    axis: np.ndarray  # (3,) angles, ASF angle unit
    axis_order: str  # e.g. "XYZ", first letter applied first
    dofs: tuple[str, ...] = ()
    line: int = 0


@dataclass
class AsfSkeleton:
    """A parsed ASF file: bones, hierarchy and units (lengths already in metres)."""

    path: Path
    bones: dict[str, AsfBone]
    children: dict[str, list[str]]
    root_order: tuple[str, ...]
    root_axis_order: str
    root_orientation: np.ndarray
    length_to_metres: float
    degrees: bool = True
    order: list[str] = field(default_factory=list)  # root first, parents before children

    def parent_of(self) -> dict[str, str | None]:
        """Parent name of every bone (None for the root)."""
        parents: dict[str, str | None] = {"root": None}
        for parent, kids in self.children.items():
            for kid in kids:
                parents[kid] = parent
        return parents


def _floats(tokens: list[str], path: Path, line: int, what: str) -> np.ndarray:
    try:
        values = np.array([float(t) for t in tokens], dtype=np.float64)
    except ValueError:
        raise MotionFormatError(path, f"non-numeric {what}: {' '.join(tokens)!r}", line) from None
    if not np.all(np.isfinite(values)):
        raise MotionFormatError(path, f"non-finite {what}", line)
    return values


def read_asf(path: str | Path) -> AsfSkeleton:
    """Parse an ASF skeleton file.

    Raises:
        MotionFormatError: naming the file and line of the first problem.
    """
    path = Path(path)
    text = read_motion_text(path, "ASF")
    lines = text.splitlines()

    length_unit = 1.0
    degrees = True
    root_order: tuple[str, ...] = ("tx", "ty", "tz", "rx", "ry", "rz")
    root_axis_order = "XYZ"
    root_orientation = np.zeros(3)
    bones: dict[str, AsfBone] = {}
    children: dict[str, list[str]] = {}
    hierarchy_lines: dict[str, int] = {}
    section = ""
    current: dict[str, object] | None = None
    seen_bonedata = seen_hierarchy = False

    def finish_bone(end_line: int) -> None:
        assert current is not None
        start = int(current["line"])  # type: ignore[arg-type]
        for key in ("name", "direction", "length"):
            if key not in current:
                raise MotionFormatError(path, f"bone block lacks '{key}'", start)
        name = str(current["name"])
        if name in bones or name == "root":
            raise MotionFormatError(path, f"duplicate bone name {name!r}", start)
        direction = np.asarray(current["direction"], dtype=np.float64)
        norm = float(np.linalg.norm(direction))
        length = float(current["length"])  # type: ignore[arg-type]
        if norm == 0.0 and length != 0.0:
            raise MotionFormatError(path, f"bone {name!r} has a zero direction", start)
        bones[name] = AsfBone(
            name=name,
            direction=direction / norm if norm > 0 else direction,
            length=length,
            axis=np.asarray(current.get("axis", np.zeros(3)), dtype=np.float64),
            axis_order=str(current.get("axis_order", "XYZ")),
            dofs=tuple(current.get("dofs", ())),  # type: ignore[arg-type]
            line=start,
        )

    for lineno, raw in enumerate(lines, start=1):
        stripped = raw.strip()
        if not stripped or stripped.startswith("#"):
            continue
        tokens = stripped.split()
        key = tokens[0].lower()
        if key.startswith(":"):
            if current is not None:
                raise MotionFormatError(path, "bone block not closed by 'end'", lineno)
            section = key
            if key == ":units":
                pass
            elif key == ":bonedata":
                seen_bonedata = True
            elif key == ":hierarchy":
                seen_hierarchy = True
            continue
        if section == ":units":
            if key == "length":
                unit = _floats(tokens[1:2], path, lineno, "length unit")
                if unit.size != 1 or unit[0] <= 0:
                    raise MotionFormatError(path, "length unit must be a positive number", lineno)
                length_unit = float(unit[0])
            elif key == "angle":
                if len(tokens) < 2 or tokens[1].lower() not in ("deg", "rad"):
                    raise MotionFormatError(path, "angle unit must be 'deg' or 'rad'", lineno)
                degrees = tokens[1].lower() == "deg"
        elif section == ":root":
            if key == "order":
                order = tuple(t.lower() for t in tokens[1:])
                if not order or any(t not in _ALL_DOFS[:6] for t in order):
                    raise MotionFormatError(path, f"bad root order {stripped!r}", lineno)
                root_order = order
            elif key == "axis":
                axis_order = tokens[1].upper() if len(tokens) > 1 else ""
                if sorted(axis_order) != ["X", "Y", "Z"]:
                    raise MotionFormatError(path, f"bad root axis {stripped!r}", lineno)
                root_axis_order = axis_order
            elif key == "orientation":
                root_orientation = _floats(tokens[1:], path, lineno, "root orientation")
                if root_orientation.size != 3:
                    raise MotionFormatError(path, "root orientation needs 3 angles", lineno)
        elif section == ":bonedata":
            if key == "begin":
                if current is not None:
                    raise MotionFormatError(path, "'begin' inside a bone block", lineno)
                current = {"line": lineno}
            elif key == "end":
                if current is None:
                    raise MotionFormatError(path, "'end' without 'begin'", lineno)
                finish_bone(lineno)
                current = None
            elif current is None:
                raise MotionFormatError(path, f"unexpected {tokens[0]!r} outside a bone block", lineno)
            elif key == "name":
                if len(tokens) != 2:
                    raise MotionFormatError(path, "bone name must be one word", lineno)
                current["name"] = tokens[1]
            elif key == "direction":
                direction = _floats(tokens[1:], path, lineno, "direction")
                if direction.size != 3:
                    raise MotionFormatError(path, "direction needs 3 numbers", lineno)
                current["direction"] = direction
            elif key == "length":
                length = _floats(tokens[1:], path, lineno, "length")
                if length.size != 1 or length[0] < 0:
                    raise MotionFormatError(path, "length needs one non-negative number", lineno)
                current["length"] = float(length[0])
            elif key == "axis":
                if len(tokens) != 5 or sorted(tokens[4].upper()) != ["X", "Y", "Z"]:
                    raise MotionFormatError(path, f"axis needs 3 angles and an order: {stripped!r}", lineno)
                current["axis"] = _floats(tokens[1:4], path, lineno, "axis")
                current["axis_order"] = tokens[4].upper()
            elif key == "dof":
                dofs = tuple(t.lower() for t in tokens[1:])
                bad = [d for d in dofs if d not in _ROT_DOFS]
                if bad:
                    raise MotionFormatError(
                        path, f"unsupported dof {bad[0]!r} (only rx ry rz are supported)", lineno
                    )
                current["dofs"] = dofs
            # id, limits (and their continuation lines), bodymass, cofmass: not needed
        elif section == ":hierarchy":
            if key in ("begin", "end"):
                continue
            parent, kids = tokens[0], tokens[1:]
            if parent != "root" and parent not in bones:
                raise MotionFormatError(path, f"hierarchy names unknown bone {parent!r}", lineno)
            for kid in kids:
                if kid not in bones:
                    raise MotionFormatError(path, f"hierarchy names unknown bone {kid!r}", lineno)
                if kid in hierarchy_lines:
                    raise MotionFormatError(path, f"bone {kid!r} has two parents", lineno)
                hierarchy_lines[kid] = lineno
            children.setdefault(parent, []).extend(kids)
    if current is not None:
        raise MotionFormatError(path, "file ends inside a bone block", len(lines))
    if not seen_bonedata or not bones:
        raise MotionFormatError(path, "no :bonedata section", len(lines) or None)
    if not seen_hierarchy:
        raise MotionFormatError(path, "no :hierarchy section", len(lines) or None)

    order = ["root"]
    frontier = ["root"]
    while frontier:
        name = frontier.pop(0)
        for kid in children.get(name, []):
            if kid in order:
                raise MotionFormatError(path, f"hierarchy cycle at {kid!r}", hierarchy_lines[kid])
            order.append(kid)
            frontier.append(kid)
    missing = [name for name in bones if name not in order]
    if missing:
        raise MotionFormatError(
            path, f"bone {missing[0]!r} is not connected to the root in :hierarchy", bones[missing[0]].line
        )
    to_m = INCH / length_unit
    for bone in bones.values():
        bone.length *= to_m
    return AsfSkeleton(
        path=path,
        bones=bones,
        children=children,
        root_order=root_order,
        root_axis_order=root_axis_order,
        root_orientation=root_orientation,
        length_to_metres=to_m,
        degrees=degrees,
        order=order,
    )


def _dof_counts(skeleton: AsfSkeleton) -> dict[str, int]:
    ndof = {name: len(b.dofs) for name, b in skeleton.bones.items()}
    ndof["root"] = len(skeleton.root_order)
    return ndof


def _parse_amc(path: Path, skeleton: AsfSkeleton) -> tuple[dict[str, np.ndarray], bool]:
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
    if start < 0 or not lines[start].strip().isdigit():
        return None
    layout: list[tuple[str, int]] = []
    for raw in lines[start + 1 :]:
        words = raw.split()
        if not words:
            continue
        if len(words) == 1 and words[0].isdigit():
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
        if len(tokens) == 1 and first.isdigit():
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


def read_amc(
    path: str | Path, asf: str | Path | AsfSkeleton, *, fps: float = DEFAULT_FPS
) -> RigMotion:
    """Read an AMC motion on its ASF skeleton into global joint positions.

    Args:
        path: the ``.amc`` file.
        asf: its ``.asf`` file (or an already parsed :class:`AsfSkeleton`).
        fps: capture rate of the trial (CMU: 120, a few trials 60).
    Returns:
        RigMotion with joints "root", every ASF bone (its end point) and then the derived
        :data:`ASF_SITES` (``head_centre``), (T, J, 3) metres, Y-up.
    Raises:
        MotionFormatError: naming the file and line of a malformed or truncated input.
    """
    path = Path(path)
    skeleton = asf if isinstance(asf, AsfSkeleton) else read_asf(asf)
    data, degrees = _parse_amc(path, skeleton)
    num_frames = next(iter(data.values())).shape[0]

    root_vals = data.get("root", np.zeros((num_frames, 0)))
    translation = np.zeros((num_frames, 3))
    rot_axes: list[str] = []
    rot_cols: list[int] = []
    for col, dof in enumerate(skeleton.root_order):
        if dof.startswith("t"):
            translation[:, "xyz".index(dof[1])] = root_vals[:, col] * skeleton.length_to_metres
        else:
            rot_axes.append(dof[1].upper())
            rot_cols.append(col)
    # dofs listed first are applied first: reverse for the outermost-first helper
    root_m = euler_to_matrix(
        root_vals[:, rot_cols[::-1]], "".join(rot_axes[::-1]), degrees=degrees
    )
    c_root = euler_to_matrix(
        skeleton.root_orientation[::-1], skeleton.root_axis_order[::-1], degrees=skeleton.degrees
    )
    parent_of = skeleton.parent_of()
    names = skeleton.order
    index = {name: i for i, name in enumerate(names)}
    rotations = np.empty((num_frames, len(names), 3, 3))
    positions = np.empty((num_frames, len(names), 3))
    rotations[:, 0] = c_root @ root_m @ c_root.T
    positions[:, 0] = translation
    for i, name in enumerate(names[1:], start=1):
        bone = skeleton.bones[name]
        parent = index[parent_of[name]]  # type: ignore[index]
        c = euler_to_matrix(bone.axis[::-1], bone.axis_order[::-1], degrees=skeleton.degrees)
        if bone.dofs:
            m = euler_to_matrix(
                data[name][:, ::-1], "".join(d[1].upper() for d in bone.dofs[::-1]), degrees=degrees
            )
            rotations[:, i] = rotations[:, parent] @ (c @ m @ c.T)
        else:
            rotations[:, i] = rotations[:, parent]
        offset = bone.direction * bone.length
        positions[:, i] = positions[:, parent] + rotations[:, i] @ offset
    parents = tuple(-1 if parent_of[n] is None else index[parent_of[n]] for n in names)  # type: ignore[index]
    names, parents, positions = _add_sites(skeleton, list(names), parents, positions, rotations)
    return RigMotion(
        names=tuple(names),
        parents=parents,
        positions=positions.astype(np.float32),
        fps=fps,
        source=path,
        meta={"asf": skeleton.path},
    )


ASF_SITES: tuple[tuple[str, str, tuple[float, float, float]], ...] = (
    ("head_centre", "head", (0.0, -1.26, 0.77)),
    ("lshoulder_centre", "lclavicle", (0.0, -0.11, -0.14)),
    ("rshoulder_centre", "rclavicle", (0.0, -0.11, -0.14)),
)
"""Derived points: (name, bone, (left, up, forward) offset from the bone's end point, in
units of that bone's length, along the skeleton's rest-pose axes); each moves rigidly with
its bone. Added only when the skeleton has the bone.

- ``head_centre``: SMPL's head joint (centre-low of the skull, about 5-6 cm in front of
  and 6-8 cm above the neck base). CMU's ``upperneck``/``head`` bones run up the back of
  the neck and skull (in the rest pose the ``upperneck`` end is 3-4 cm *behind* the neck
  base), so the site lies 1.26 head-bone lengths below the head bone's end (the top of the
  skull) and 0.77 in front of it.
- ``l/rshoulder_centre``: the glenohumeral centre. The clavicle bone ends at the top front
  of the shoulder, 2-3 cm higher and further forward than SMPL's shoulder joint.
"""


def rest_frame(skeleton: AsfSkeleton) -> np.ndarray:
    """(3, 3) rows: the rest pose's left, up (+Y) and forward axes in ASF global coordinates.

    Left is the horizontal direction from ``rhipjoint`` to ``lhipjoint`` (the CMU rest pose
    faces +Z with its left towards +X, the fallback when the hips are missing).
    """
    up = np.array([0.0, 1.0, 0.0])
    left = np.array([1.0, 0.0, 0.0])
    bones = skeleton.bones
    if "lhipjoint" in bones and "rhipjoint" in bones:
        d = bones["lhipjoint"].direction - bones["rhipjoint"].direction
        d = d - d[1] * up
        if np.linalg.norm(d) > 1e-6:
            left = d / np.linalg.norm(d)
    return np.stack([left, up, np.cross(left, up)])


def _add_sites(
    skeleton: AsfSkeleton, names: list[str], parents: tuple[int, ...], positions: np.ndarray,
    rotations: np.ndarray,
) -> tuple[list[str], tuple[int, ...], np.ndarray]:
    """Append :data:`ASF_SITES` whose bone exists (end of the bone + rotated rest offset)."""
    frame = rest_frame(skeleton)
    extra, extra_parents, extra_names = [], [], []
    for site, bone, (left, up, forward) in ASF_SITES:
        if bone not in skeleton.bones or site in names:
            continue
        i = names.index(bone)
        offset = skeleton.bones[bone].length * (left * frame[0] + up * frame[1] + forward * frame[2])
        extra.append(positions[:, i] + rotations[:, i] @ offset)
        extra_parents.append(i)
        extra_names.append(site)
    if not extra:
        return names, parents, positions
    return (names + extra_names, parents + tuple(extra_parents),
            np.concatenate([positions, np.stack(extra, axis=1)], axis=1))


def find_asf(amc_path: str | Path) -> Path | None:
    """The ASF of a CMU trial ``SS_TT.amc``: ``SS.asf`` beside it or in a sibling ``asf/``.

    Returns None when no candidate exists.
    """
    amc_path = Path(amc_path)
    subject = amc_path.stem.split("_")[0]
    for folder in (amc_path.parent, amc_path.parent.parent / "asf", amc_path.parent / "asf"):
        for name in (f"{subject}.asf", f"{subject}.ASF"):
            candidate = folder / name
            if candidate.is_file():
                return candidate
    return None


def lookup_cmu_fps(amc_path: str | Path) -> float | None:
    """Capture rate of CMU trial ``SS_TT.amc`` from a ``CMU_data.csv`` index, if one is found.

    Looks beside the AMC file and one folder up (the shared-data layout ``cmu/amc/``,
    ``cmu/CMU_data.csv``); the CSV has columns "Subject", "Trial #" and "framerate".
    """
    amc_path = Path(amc_path)
    parts = amc_path.stem.split("_")
    if len(parts) != 2 or not all(p.isdigit() for p in parts):
        return None
    subject, trial = int(parts[0]), int(parts[1])
    for folder in (amc_path.parent, amc_path.parent.parent):
        index = folder / "CMU_data.csv"
        if not index.is_file():
            continue
        try:
            with open(index, newline="", encoding="utf-8", errors="replace") as handle:
                for row in csv.DictReader(handle):
                    try:
                        if int(row["Subject"]) == subject and int(row["Trial #"]) == trial:
                            return float(row["framerate"])
                    except (KeyError, TypeError, ValueError):
                        continue
        except OSError:
            continue
    return None
