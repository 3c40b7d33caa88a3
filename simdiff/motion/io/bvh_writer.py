"""Write HumanML3D joint positions as a BVH animation of the 22-joint skeleton.

The file follows Blender's BVH importer conventions: lengths in metres (import with
Scale 1.0), Y up and the character facing +Z (Blender's default "Forward -Z, Up Y" import
maps it to Blender's Z-up), rotation channels composed outermost-first in the listed
order, the root's position channels giving its global position (root OFFSET is zero).

Rest pose: T-pose-like, each bone along its HumanML3D ``RAW_OFFSETS`` direction with the
motion's mean bone length; the two branching joints (pelvis: hips + spine1; spine3:
neck + collars) keep the mean shape of their child triangle as measured in the motion,
so a rigid triangle is fitted exactly. Rotations are solved from positions: branching
joints by a Kabsch (SVD) fit of their children, chain joints by the shortest rotation
(no twist relative to the parent) that aims the bone from the already-placed parent at
its target, so limb chains reproduce the input up to bone-length changes.

Motions whose bone lengths change over time (generated ones, recovered from root-relative
positions, vary by several millimetres) also get position channels on every joint: the
motion's own per-frame offset of each joint in its parent's frame, so that reading the file
back gives the input joints to the printed precision (joints → BVH → joints ≤ 1 µm here,
instead of tens of millimetres with fixed bones). Constant-length rigs keep rotation-only
joints.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np

from simdiff.errors import SimdiffError
from simdiff.fsio import write_text
from simdiff.motion.io.euler import matrix_to_euler
from simdiff.motion.skeleton import FPS, JOINT_NAMES, NUM_JOINTS, PARENTS, RAW_OFFSETS

ROOT_ORDER: str = "ZXY"
"""Root rotation channels (yaw about Y innermost, so turning never meets gimbal lock)."""
JOINT_ORDER: str = "ZYX"
"""Other joints (twist about the bone's Y axis in the middle, away from +-90 degrees)."""

STRETCH_TOLERANCE: float = 1e-5
"""Bone-length range (metres) above which joints get per-frame position channels."""

_BRANCHES: dict[int, tuple[int, int, int]] = {0: (1, 2, 3), 9: (13, 14, 12)}
"""Branching joint -> (left child, right child, up child)."""


def _children() -> list[list[int]]:
    kids: list[list[int]] = [[] for _ in range(NUM_JOINTS)]
    for j, p in enumerate(PARENTS):
        if p >= 0:
            kids[p].append(j)
    return kids


def _unit(v: np.ndarray) -> np.ndarray:
    norm = np.linalg.norm(v, axis=-1, keepdims=True)
    return v / np.maximum(norm, 1e-12)


def _rotation_between(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Shortest rotations (..., 3, 3) taking directions a onto b (antiparallel: any 180 deg)."""
    a, b = _unit(a), _unit(b)
    a = np.broadcast_to(a, b.shape)
    axis = np.cross(a, b)
    sin = np.linalg.norm(axis, axis=-1)
    cos = np.sum(a * b, axis=-1)
    # antiparallel: rotate pi about any axis perpendicular to a
    helper = np.where(np.abs(a[..., :1]) < 0.9, [1.0, 0.0, 0.0], [0.0, 1.0, 0.0])
    perp = _unit(np.cross(a, helper))
    flip = sin < 1e-9
    axis = np.where(flip[..., None], perp, axis / np.maximum(sin, 1e-12)[..., None])
    angle = np.arctan2(sin, cos)
    angle = np.where(flip & (cos > 0), 0.0, angle)
    x, y, z = axis[..., 0], axis[..., 1], axis[..., 2]
    zero = np.zeros_like(x)
    k = np.stack(
        [np.stack([zero, -z, y], -1), np.stack([z, zero, -x], -1), np.stack([-y, x, zero], -1)], -2
    )
    s, c = np.sin(angle)[..., None, None], np.cos(angle)[..., None, None]
    return np.eye(3) + s * k + (1.0 - c) * (k @ k)


def _kabsch(rest: np.ndarray, current: np.ndarray) -> np.ndarray:
    """Rotations (T, 3, 3) minimising sum_k |R rest_k - current_tk|^2; rest (K, 3)."""
    h = np.einsum("tki,kj->tij", current, rest)
    u, _, vt = np.linalg.svd(h)
    d = np.sign(np.linalg.det(u @ vt))
    fix = np.ones(u.shape[:-2] + (3,))
    fix[..., 2] = np.where(d == 0, 1.0, d)
    return (u * fix[..., None, :]) @ vt


def _branch_frame(left: np.ndarray, right: np.ndarray, up: np.ndarray) -> np.ndarray:
    """(T, 3, 3) frames (columns x, y, z): x from right to left child, y towards ``up``."""
    x = _unit(left - right)
    y = _unit(up - np.sum(up * x, axis=-1, keepdims=True) * x)
    return np.stack([x, y, np.cross(x, y)], axis=-1)


def rest_offsets(joints: np.ndarray) -> np.ndarray:
    """(22, 3) rest-pose offsets in metres of each joint from its parent (row 0 zero).

    Args:
        joints: (T, 22, 3) positions in metres.
    """
    joints = np.asarray(joints, dtype=np.float64)
    parents = np.asarray(PARENTS)
    offsets = np.zeros((NUM_JOINTS, 3))
    vectors = joints[:, 1:] - joints[:, parents[1:]]
    lengths = np.linalg.norm(vectors, axis=-1).mean(axis=0)
    offsets[1:] = RAW_OFFSETS[1:] * lengths[:, None]
    for joint, (left, right, up) in _BRANCHES.items():
        frame = _branch_frame(
            joints[:, left] - joints[:, joint],
            joints[:, right] - joints[:, joint],
            joints[:, up] - joints[:, joint],
        )
        for child in (left, right, up):
            local = np.einsum("tij,ti->tj", frame, joints[:, child] - joints[:, joint])
            offsets[child] = local.mean(axis=0)
    return offsets


def solve_rotations(joints: np.ndarray, offsets: np.ndarray) -> np.ndarray:
    """Local rotations (T, 22, 3, 3) that pose ``offsets`` like ``joints``.

    Row 0 is the root's global rotation; leaves (head, feet, wrists) get the identity.
    """
    joints = np.asarray(joints, dtype=np.float64)
    num_frames = joints.shape[0]
    kids = _children()
    global_rot = np.empty((num_frames, NUM_JOINTS, 3, 3))
    local_rot = np.empty((num_frames, NUM_JOINTS, 3, 3))
    placed = np.empty_like(joints)
    placed[:, 0] = joints[:, 0]
    for j in range(NUM_JOINTS):
        parent = PARENTS[j]
        parent_rot = global_rot[:, parent] if parent >= 0 else np.broadcast_to(np.eye(3), (num_frames, 3, 3))
        if parent >= 0:
            placed[:, j] = placed[:, parent] + parent_rot @ offsets[j]
        if j in _BRANCHES:
            children = list(_BRANCHES[j])
            current = joints[:, children] - placed[:, j, None]
            rot = _kabsch(offsets[children], current)
            global_rot[:, j] = rot
            local_rot[:, j] = np.swapaxes(parent_rot, -1, -2) @ rot
        elif kids[j]:
            (child,) = kids[j]
            target = joints[:, child] - placed[:, j]
            in_parent = np.einsum("tji,tj->ti", parent_rot, target)
            local = _rotation_between(offsets[child], in_parent)
            short = np.linalg.norm(target, axis=-1) < 1e-9
            local[short] = np.eye(3)
            local_rot[:, j] = local
            global_rot[:, j] = parent_rot @ local
        else:
            local_rot[:, j] = np.eye(3)
            global_rot[:, j] = parent_rot
    return local_rot


def global_rotations(local: np.ndarray) -> np.ndarray:
    """Global rotations (T, 22, 3, 3) from local ones (row 0 the root's global rotation)."""
    out = np.empty_like(local)
    for j in range(NUM_JOINTS):
        parent = PARENTS[j]
        out[:, j] = local[:, j] if parent < 0 else out[:, parent] @ local[:, j]
    return out


def local_translations(joints: np.ndarray, local: np.ndarray) -> np.ndarray:
    """(T, 22, 3) offset of each joint from its parent in the parent's frame (row 0: root position)."""
    joints = np.asarray(joints, dtype=np.float64)
    glob = global_rotations(local)
    parents = np.asarray(PARENTS)
    out = np.empty_like(joints)
    out[:, 0] = joints[:, 0]
    delta = joints[:, 1:] - joints[:, parents[1:]]
    out[:, 1:] = np.einsum("tjki,tjk->tji", glob[:, parents[1:]], delta)
    return out


def bones_stretch(joints: np.ndarray, tolerance: float = STRETCH_TOLERANCE) -> bool:
    """Whether any bone of (T, 22, 3) ``joints`` changes length by more than ``tolerance`` metres."""
    joints = np.asarray(joints, dtype=np.float64)
    parents = np.asarray(PARENTS)
    lengths = np.linalg.norm(joints[:, 1:] - joints[:, parents[1:]], axis=-1)
    return bool(np.any(lengths.max(axis=0) - lengths.min(axis=0) > tolerance))


def _hierarchy_lines(offsets: np.ndarray, positions: bool = False) -> list[str]:
    kids = _children()
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
            if positions:
                lines.append(f"{pad}  CHANNELS 6 Xposition Yposition Zposition {rot}")
            else:
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
    kids = _children()
    order: list[int] = []

    def visit(j: int) -> None:
        order.append(j)
        for child in kids[j]:
            visit(child)

    visit(0)
    return order


def write_bvh(path: str | Path, joints: np.ndarray, fps: float = FPS, stretch: bool | None = None) -> Path:
    """Write (T, 22, 3) HumanML3D joint positions (metres, Y-up) as a BVH file, atomically.

    Args:
        path: output ``.bvh`` file (parent folders are created).
        joints: (T, 22, 3) positions in metres, Y-up (HumanML3D order).
        fps: frame rate (HumanML3D: 20).
        stretch: per-frame position channels on every joint (the motion's own bone lengths);
            None: only when a bone's length varies by more than :data:`STRETCH_TOLERANCE`.
    Returns:
        The path written.
    Raises:
        SimdiffError: when ``joints`` is not a finite (T, 22, 3) array with T >= 1.
    """
    joints = np.asarray(joints, dtype=np.float64)
    if joints.ndim != 3 or joints.shape[1:] != (NUM_JOINTS, 3) or joints.shape[0] < 1:
        raise SimdiffError(f"write_bvh needs joints of shape (T, 22, 3), got {joints.shape}")
    if not np.all(np.isfinite(joints)):
        raise SimdiffError("write_bvh: joints contain NaN or infinite values")
    if not fps > 0:
        raise SimdiffError(f"write_bvh: fps must be positive, got {fps}")
    offsets = rest_offsets(joints)
    local = solve_rotations(joints, offsets)
    order = _file_order()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # scipy's gimbal-lock note: angles stay valid
        root_angles = matrix_to_euler(local[:, 0], ROOT_ORDER)
        joint_angles = matrix_to_euler(local[:, order[1:]], JOINT_ORDER)
    num_frames = joints.shape[0]
    if stretch is None:
        stretch = bones_stretch(joints)
    if stretch:
        trans = local_translations(joints, local)[:, order[1:]]
        per_joint = np.concatenate([trans, joint_angles], axis=-1).reshape(num_frames, -1)
    else:
        per_joint = joint_angles.reshape(num_frames, -1)
    values = np.concatenate([joints[:, 0], root_angles, per_joint], axis=1)
    lines = _hierarchy_lines(offsets, positions=stretch)
    lines += ["MOTION", f"Frames: {joints.shape[0]}", f"Frame Time: {1.0 / fps:.8f}"]
    lines += [" ".join(f"{v:.6f}" for v in row) for row in values]
    return write_text(Path(path), "\n".join(lines) + "\n")
