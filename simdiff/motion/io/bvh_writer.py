"""Write a motion as a standard BVH animation of the 22-joint skeleton: the root with 6 channels, every other joint
with 3 rotation channels.

The file follows Blender's BVH importer conventions: lengths in metres (import with Scale 1.0), Y up and the
character facing +Z (Blender's default "Forward -Z, Up Y" import maps it to Blender's Z-up), rotation channels
composed outermost-first in the listed order, the root's position channels giving its global position (root OFFSET
is zero). The skeleton and rotations are :mod:`simdiff.motion.rigid`'s: a motion that already has constant bone
lengths and rigid pelvis and chest (what ``generate``, ``sample`` and the viewer write) reads back within 1 µm; a
motion whose bones stretch is written as its rigid fit (the rest pose is its mean skeleton).
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np

from simdiff.errors import SimdiffError
from simdiff.fsio import write_text
from simdiff.motion.io.euler import matrix_to_euler
from simdiff.motion.rigid import RigidMotion, children, fit
from simdiff.motion.skeleton import FPS, JOINT_NAMES, RAW_OFFSETS

ROOT_ORDER: str = "ZXY"
"""Root rotation channels (yaw about Y innermost, so turning never meets gimbal lock)."""
JOINT_ORDER: str = "ZYX"
"""Other joints (twist about the bone's Y axis in the middle, away from +-90 degrees)."""


def _hierarchy_lines(offsets: np.ndarray) -> list[str]:
    kids = children()
    lines = ["HIERARCHY"]

    def emit(j: int, depth: int) -> None:
        pad = "  " * depth
        keyword = "ROOT" if j == 0 else "JOINT"
        lines.append(f"{pad}{keyword} {JOINT_NAMES[j]}")
        lines.append(f"{pad}{{")
        off = offsets[j]
        lines.append(f"{pad}  OFFSET {off[0]:.6f} {off[1]:.6f} {off[2]:.6f}")
        if j == 0:
            rot = " ".join(f"{a}rotation" for a in ROOT_ORDER)
            lines.append(f"{pad}  CHANNELS 6 Xposition Yposition Zposition {rot}")
        else:
            rot = " ".join(f"{a}rotation" for a in JOINT_ORDER)
            lines.append(f"{pad}  CHANNELS 3 {rot}")
        if kids[j]:
            for child in kids[j]:
                emit(child, depth + 1)
        else:
            end = RAW_OFFSETS[j] * 0.5 * float(np.linalg.norm(offsets[j]))
            lines.append(f"{pad}  End Site")
            lines.append(f"{pad}  {{")
            lines.append(f"{pad}    OFFSET {end[0]:.6f} {end[1]:.6f} {end[2]:.6f}")
            lines.append(f"{pad}  }}")
        lines.append(f"{pad}}}")

    emit(0, 0)
    return lines


def _file_order() -> list[int]:
    """Joint indices in the depth-first order the hierarchy lists them (channel order)."""
    kids = children()
    order: list[int] = []

    def visit(j: int) -> None:
        order.append(j)
        for child in kids[j]:
            visit(child)

    visit(0)
    return order


def write_bvh(path: str | Path, joints: np.ndarray, fps: float = FPS) -> Path:
    """Write (T, 22, 3) joint positions (metres, Y-up, HumanML3D order) as a BVH file, atomically.

    The rotations are :func:`simdiff.motion.rigid.fit` on the motion's own mean skeleton.

    Raises:
        SimdiffError: when ``joints`` is not a finite (T, 22, 3) array with T >= 1, or ``fps`` ≤ 0.
    """
    joints = np.asarray(joints, dtype=np.float64)
    if joints.ndim != 3 or joints.shape[1:] != (22, 3) or joints.shape[0] < 1:
        raise SimdiffError(f"write_bvh needs joints of shape (T, 22, 3), got {joints.shape}")
    if not np.all(np.isfinite(joints)):
        raise SimdiffError("write_bvh: joints contain NaN or infinite values")
    return write_rigid_bvh(path, fit(joints, None), fps)


def write_rigid_bvh(path: str | Path, motion: RigidMotion, fps: float = FPS) -> Path:
    """Write a :class:`~simdiff.motion.rigid.RigidMotion` as a BVH file, atomically; its forward kinematics is
    ``motion.joints`` up to the printed digits (6 decimals)."""
    if not (np.isfinite(fps) and fps > 0):
        raise SimdiffError(f"write_bvh: fps must be a positive number, got {fps}")
    local = motion.local
    order = _file_order()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # scipy's gimbal-lock note: angles stay valid
        root_angles = matrix_to_euler(local[:, 0], ROOT_ORDER)
        joint_angles = matrix_to_euler(local[:, order[1:]], JOINT_ORDER)
    num_frames = local.shape[0]
    values = np.concatenate([motion.root, root_angles, joint_angles.reshape(num_frames, -1)], axis=1)
    lines = _hierarchy_lines(motion.offsets)
    lines += ["MOTION", f"Frames: {num_frames}", f"Frame Time: {1.0 / fps:.8f}"]
    lines += [" ".join(f"{v:.6f}" for v in row) for row in values]
    return write_text(Path(path), "\n".join(lines) + "\n")
