"""HumanML3D's 263-dim motion features: joints → features and back.

Layout of one row (0-based slices, see :data:`SLICES`)::

    [0]       root angular velocity about Y: half the yaw increment of the world→heading
              rotation (rad/frame); a left turn (towards +X) is negative
    [1:3]     root linear velocity (x, z) in the heading frame (m/frame)
    [3]       root height (m above the floor)
    [4:67]    "ric": joints 1..21 relative to the root in XZ, in the heading frame (m)
    [67:193]  local rotations of joints 1..21, continuous 6D
    [193:259] velocities of all 22 joints in the heading frame (m/frame)
    [259:263] foot contacts: left ankle, left toe, right ankle, right toe (0/1)

Row t holds root and joint velocities for t → t+1, so T joint frames give T−1 rows.
All inputs and outputs are metres, Y-up, 20 fps; outputs are float32.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import torch

from simdiff.errors import SimdiffError
from simdiff.motion import quaternion as Q
from simdiff.motion.kinematics import facing_direction, forward_kinematics, forward_kinematics_matrix, inverse_kinematics
from simdiff.motion.skeleton import CANONICAL_OFFSETS, FACE_JOINTS, FOOT_LEFT, FOOT_RIGHT, LEG_JOINTS, NUM_JOINTS, bone_offsets

FEATURE_DIM: int = 263
FEET_THRESHOLD: float = 0.002
"""Squared per-frame foot displacement (m²) below which a foot is in contact."""

SLICES: dict[str, slice] = {
    "root_rot_vel": slice(0, 1),
    "root_lin_vel": slice(1, 3),
    "root_y": slice(3, 4),
    "ric": slice(4, 67),
    "rot6d": slice(67, 193),
    "vel": slice(193, 259),
    "contacts": slice(259, 263),
}
"""Named slices of the 263-dim feature vector."""


def _check_joints(joints: np.ndarray, min_frames: int = 2) -> np.ndarray:
    arr = np.asarray(joints)
    if arr.ndim != 3 or arr.shape[1:] != (NUM_JOINTS, 3):
        raise SimdiffError(f"expected joints of shape (T, 22, 3), got {tuple(arr.shape)}")
    if arr.shape[0] < min_frames:
        raise SimdiffError(f"need at least {min_frames} frames of joints, got {arr.shape[0]}")
    if not np.all(np.isfinite(arr)):
        raise SimdiffError("joints contain NaN or infinite values")
    return arr.astype(np.float64)


def _check_features(features: np.ndarray | torch.Tensor) -> None:
    if features.ndim < 2 or features.shape[-1] != FEATURE_DIM:
        raise SimdiffError(f"expected features of shape (..., T, 263), got {tuple(features.shape)}")


def retarget_uniform(
    joints: np.ndarray, target_offsets: np.ndarray = CANONICAL_OFFSETS, *, hip_quirk: bool = True
) -> np.ndarray:
    """Retarget a motion to the canonical bone lengths, keeping bone directions.

    The root trajectory is scaled by the ratio of leg lengths (|offset| of knee and
    ankle along their rest axis), as HumanML3D does.

    Args:
        joints: (T, 22, 3) positions in metres.
        target_offsets: (22, 3) rest offsets of the target skeleton.
    Returns:
        (T, 22, 3) float64 positions.
    """
    pos = _check_joints(joints, min_frames=1)
    quats = inverse_kinematics(pos, smooth_forward=False, hip_quirk=hip_quirk)
    return forward_kinematics(quats, pos[:, 0] * uniform_scale(pos, target_offsets), target_offsets)


def uniform_scale(joints: np.ndarray, target_offsets: np.ndarray = CANONICAL_OFFSETS) -> float:
    """The factor :func:`retarget_uniform` scales the root path by: the target's leg length over that of
    ``joints``' first frame ((T, 22, 3) metres)."""

    def leg(offsets: np.ndarray) -> float:
        return float(sum(np.abs(offsets[j]).max() for j in LEG_JOINTS))

    return leg(target_offsets) / leg(bone_offsets(np.asarray(joints, dtype=np.float64)[0]))


def canonicalize(joints: np.ndarray) -> np.ndarray:
    """Put a motion on the floor (min y = 0), root XZ at the origin and facing +Z at frame 0.

    Args:
        joints: (T, 22, 3) positions in metres.
    Returns:
        (T, 22, 3) float64 positions.
    """
    pos = _check_joints(joints, min_frames=1).copy()
    pos[..., 1] -= pos[..., 1].min()
    pos -= pos[0, 0] * np.array([1.0, 0.0, 1.0])
    q0 = facing_rotation(pos)
    return Q.qrot(np.broadcast_to(q0, pos.shape[:-1] + (4,)), pos)


def facing_rotation(joints: np.ndarray) -> np.ndarray:
    """(4,) quaternion (w, x, y, z) of the yaw that turns ``joints``' ((T, 22, 3)) frame-0 facing to +Z, as
    :func:`canonicalize` applies it."""
    forward = facing_direction(np.asarray(joints, dtype=np.float64)[:1], FACE_JOINTS)
    return Q.qbetween(forward, np.array([[0.0, 0.0, 1.0]]))[0]


@dataclass
class ProcessedMotion:
    """Result of :func:`process_joints`.

    Attributes:
        features: (T-1, 263) float32 features.
        joints: (T, 22, 3) float32 canonical joints (uniform skeleton, on the floor,
            facing +Z at frame 0), the positions the features describe.
    """

    features: np.ndarray
    joints: np.ndarray


def process_joints(
    joints: np.ndarray,
    *,
    feet_threshold: float = FEET_THRESHOLD,
    uniform_skeleton: bool = True,
    hip_quirk: bool = True,
    canonical: bool = True,
    yaw_sign_fix: bool = True,
) -> ProcessedMotion:
    """HumanML3D's processing of joint positions into 263-dim features.

    Args:
        joints: (T, 22, 3) positions, metres, Y-up, 20 fps, T ≥ 2.
        feet_threshold: squared displacement (m²/frame²) under which a foot is in contact.
        uniform_skeleton: retarget to the canonical bone lengths first.
        hip_quirk: reproduce HumanML3D's hip/shoulder index quirk in the IK (default,
            needed to match the dataset); False uses the consistent facing.
        canonical: put on the floor, at the origin and facing +Z first.
        yaw_sign_fix: take the per-frame yaw increment on the w ≥ 0 hemisphere. The
            original code does not, so its root angular velocity flips sign for the one
            frame where the heading crosses ±180° (a 2·|Δyaw| glitch in the recovered
            trajectory); False reproduces that.
    Returns:
        The features (T-1, 263) and the canonical joints they describe.
    """
    pos = _check_joints(joints)
    if uniform_skeleton:
        pos = retarget_uniform(pos, hip_quirk=hip_quirk)
    if canonical:
        pos = canonicalize(pos)
    n = pos.shape[0]

    disp = np.sum((pos[1:] - pos[:-1]) ** 2, axis=-1)
    contacts = np.concatenate(
        [disp[:, list(FOOT_LEFT)] < feet_threshold, disp[:, list(FOOT_RIGHT)] < feet_threshold], axis=-1
    )

    quats = inverse_kinematics(pos, smooth_forward=True, hip_quirk=hip_quirk)
    r_rot = quats[:, 0]
    cont6d = Q.quat_to_cont6d(quats)
    root_vel = Q.qrot(r_rot[1:], pos[1:, 0] - pos[:-1, 0])
    rot_vel = Q.qmul(r_rot[1:], Q.qinv(r_rot[:-1]))
    if yaw_sign_fix:
        rot_vel = np.where(rot_vel[:, :1] < 0, -rot_vel, rot_vel)

    ric = pos.copy()
    ric[..., 0] -= pos[:, :1, 0]
    ric[..., 2] -= pos[:, :1, 2]
    ric = Q.qrot(np.broadcast_to(r_rot[:, None], ric.shape[:-1] + (4,)), ric)
    local_vel = Q.qrot(np.broadcast_to(r_rot[:-1, None], (n - 1, NUM_JOINTS, 4)), pos[1:] - pos[:-1])

    features = np.concatenate(
        [
            np.arcsin(np.clip(rot_vel[:, 2:3], -1.0, 1.0)),
            root_vel[:, [0, 2]],
            pos[:-1, 0, 1:2],
            ric[:-1, 1:].reshape(n - 1, -1),
            cont6d[:-1, 1:].reshape(n - 1, -1),
            local_vel.reshape(n - 1, -1),
            contacts.astype(np.float64),
        ],
        axis=-1,
    )
    return ProcessedMotion(features=features.astype(np.float32), joints=pos.astype(np.float32))


def joints_to_features(joints: np.ndarray, **kwargs: object) -> np.ndarray:
    """(T, 22, 3) joints → (T-1, 263) float32 features; options as :func:`process_joints`."""
    return process_joints(joints, **kwargs).features  # type: ignore[arg-type]


def _root_rotation_position(features: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
    """Integrate root yaw (half-angles, (..., T)) and position ((..., T, 3)) from features."""
    half = torch.zeros_like(features[..., 0])
    half[..., 1:] = features[..., :-1, 0]
    half = torch.cumsum(half, dim=-1)
    vel = torch.zeros(features.shape[:-1] + (3,), dtype=features.dtype, device=features.device)
    vel[..., 1:, 0] = features[..., :-1, 1]
    vel[..., 1:, 2] = features[..., :-1, 2]
    root = torch.cumsum(_unrotate_yaw(half, vel), dim=-2)
    root[..., 1] = features[..., 3]
    return half, root


def _unrotate_yaw(half: torch.Tensor, v: torch.Tensor) -> torch.Tensor:
    """Rotate vectors (..., 3) by the inverse of the yaw whose half-angle is ``half`` (...)."""
    c, s = torch.cos(2 * half), torch.sin(2 * half)
    x, y, z = v[..., 0], v[..., 1], v[..., 2]
    return torch.stack([c * x - s * z, y, s * x + c * z], dim=-1)


def features_to_joints(features: np.ndarray | torch.Tensor) -> np.ndarray | torch.Tensor:
    """Joint positions from the root and "ric" channels (HumanML3D's ``recover_from_ric``).

    Rotation, velocity and contact channels are ignored, as in evaluation.

    Args:
        features: (..., T, 263) un-normalised features (numpy or torch).
    Returns:
        (..., T, 22, 3) positions in metres, same type as the input (numpy → float32).
    """
    _check_features(features)
    as_numpy = not isinstance(features, torch.Tensor)
    f = torch.as_tensor(np.asarray(features), dtype=torch.float64) if as_numpy else features
    half, root = _root_rotation_position(f)
    local = f[..., 4 : 4 + (NUM_JOINTS - 1) * 3].reshape(f.shape[:-1] + (NUM_JOINTS - 1, 3))
    local = _unrotate_yaw(half[..., None], local)
    local = local + torch.stack(
        [root[..., 0], torch.zeros_like(root[..., 0]), root[..., 2]], dim=-1
    ).unsqueeze(-2)
    joints = torch.cat([root.unsqueeze(-2), local], dim=-2)
    return joints.numpy().astype(np.float32) if as_numpy else joints


def features_to_joints_fk(features: np.ndarray, offsets: np.ndarray = CANONICAL_OFFSETS) -> np.ndarray:
    """Joint positions by forward kinematics of the rot6d channels (``recover_from_rot``).

    Args:
        features: (T, 263) un-normalised features.
        offsets: (22, 3) skeleton rest offsets (default: canonical HumanML3D bones).
    Returns:
        (T, 22, 3) float32 positions in metres.
    """
    _check_features(features)
    f = torch.as_tensor(np.asarray(features), dtype=torch.float64)
    half, root = _root_rotation_position(f)
    half_np = half.numpy()
    root_rot = Q.quat_to_matrix(Q.yaw_quat(half_np))
    n = f.shape[0]
    local = Q.cont6d_to_matrix(f[:, SLICES["rot6d"]].numpy().reshape(n, NUM_JOINTS - 1, 6))
    rots = np.concatenate([root_rot[:, None], local], axis=1)
    joints = forward_kinematics_matrix(rots, root.numpy(), offsets)
    return joints.astype(np.float32)


def extend_last_frame(joints: np.ndarray, features: np.ndarray) -> np.ndarray:
    """Rebuild the joint frame that features → joints cannot give back.

    T feature rows describe T+1 joint frames, but ``features_to_joints`` returns T. The
    last row's root yaw and local joint velocities give frame T+1 exactly.

    Args:
        joints: (T, 22, 3) positions recovered from ``features``.
        features: (T, 263) un-normalised features.
    Returns:
        (T+1, 22, 3) float32 positions.
    """
    _check_features(features)
    f = torch.as_tensor(np.asarray(features), dtype=torch.float64)
    half, _ = _root_rotation_position(f)
    vel = f[-1, SLICES["vel"]].reshape(NUM_JOINTS, 3)
    step = _unrotate_yaw(half[-1], vel).numpy()
    last = np.asarray(joints[-1], dtype=np.float64) + step
    return np.concatenate([np.asarray(joints, dtype=np.float64), last[None]], axis=0).astype(np.float32)
