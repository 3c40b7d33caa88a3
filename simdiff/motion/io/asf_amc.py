"""Acclaim AMC motion reader (the CMU mocap format) on an ASF skeleton.

The skeleton, its units (``:units length``, metres = ``v / L * 0.0254``) and the rotation
conventions (``G = G_parent @ C @ M @ C^-1``) are documented in :mod:`simdiff.motion.io.asf`;
the AMC root translation uses the ASF length unit, angles are degrees unless ``:RADIANS``.
"""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np

from simdiff.errors import MotionFormatError
from simdiff.motion.io.amc_parse import parse_amc as _parse_amc
from simdiff.motion.io.asf import INCH, AsfBone, AsfSkeleton, read_asf
from simdiff.motion.io.euler import euler_to_matrix
from simdiff.motion.io.rates import check_fps
from simdiff.motion.io.rig import RigMotion

__all__ = ["ASF_SITES", "DEFAULT_FPS", "INCH", "AsfBone", "AsfSkeleton", "find_asf", "lookup_cmu_fps",
           "read_amc", "read_asf", "rest_frame", "amc_fps_from_name"]

DEFAULT_FPS: float = 120.0
"""Capture rate of most CMU trials (a few are 60 fps: see CMU_data.csv)."""


@np.errstate(over="ignore", invalid="ignore")
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
        FrameRateError: ``fps`` outside [1, 1000] Hz.
    """
    path = Path(path)
    fps = check_fps(fps, "fps")
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
    positions = positions.astype(np.float32)
    if not np.all(np.isfinite(positions)):  # overflowing values (warnings silenced by the decorator)
        raise MotionFormatError(path, "joint positions overflow: root translation or bone lengths too large")
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
    """The ASF skeleton of an AMC file, or None when no candidate exists.

    Candidates are named by a leading part of the AMC name cut at ``_``, shortest first:
    ``SS.asf`` for a CMU trial ``SS_TT.amc``, ``HDM_bd.asf`` for HDM05's
    ``HDM_bd_kick_001_120.amc``; each is looked for beside the AMC, in a sibling ``asf/``
    and in ``../asf/`` (also with an upper-case ``.ASF``).
    """
    amc_path = Path(amc_path)
    parts = amc_path.stem.split("_")
    folders = (amc_path.parent, amc_path.parent.parent / "asf", amc_path.parent / "asf")
    for k in range(1, len(parts)):
        stem = "_".join(parts[:k])
        for folder in folders:
            for name in (f"{stem}.asf", f"{stem}.ASF"):
                candidate = folder / name
                if candidate.is_file():
                    return candidate
    return None


def amc_fps_from_name(amc_path: str | Path) -> float | None:
    """Frame rate stated at the end of an AMC name, as HDM05's ``..._120.amc``, else None.

    Only 60, 120 and 240 are taken (CMU trial numbers like ``SS_60.amc`` are not rates:
    a name with just two parts never counts).
    """
    parts = Path(amc_path).stem.split("_")
    if len(parts) >= 3 and parts[-1] in ("60", "120", "240"):
        return float(parts[-1])
    return None


def lookup_cmu_fps(amc_path: str | Path) -> float | None:
    """Capture rate of CMU trial ``SS_TT.amc`` from a ``CMU_data.csv`` index, if one is found.

    Looks beside the AMC file and one folder up (the shared-data layout ``cmu/amc/``,
    ``cmu/CMU_data.csv``); the CSV has columns "Subject", "Trial #" and "framerate".
    """
    amc_path = Path(amc_path)
    parts = amc_path.stem.split("_")
    if len(parts) != 2 or not all(p.isascii() and p.isdecimal() and len(p) < 10 for p in parts):
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
                            rate = float(row["framerate"])
                        else:
                            continue
                    except (KeyError, TypeError, ValueError):
                        continue
                    return check_fps(rate, f"framerate of trial {amc_path.stem}", index)
        except OSError:
            continue
    return None
