"""Acclaim ASF skeleton reader (bones, hierarchy, units; the motion is in ``asf_amc``).

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

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from simdiff.errors import MotionFormatError
from simdiff.motion.io.rig import read_motion_text

INCH: float = 0.0254
"""Metres per inch."""

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
        if not np.isfinite(bone.length):
            raise MotionFormatError(path, f"bone {bone.name!r} is infinitely long in metres (length unit "
                                          f"{length_unit:g})", bone.line)
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
