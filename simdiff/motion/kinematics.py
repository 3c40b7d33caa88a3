"""Forward and inverse kinematics on the HumanML3D skeleton (numpy, float64 inside).

Rotations are per-joint local quaternions (w, x, y, z) relative to the raw-offset T-pose of
:mod:`simdiff.motion.skeleton` (not the SMPL rest pose). As in HumanML3D, every kinematic
chain starts from the root rotation, so e.g. the collars' rotations are relative to the
pelvis, not to spine3.
"""

from __future__ import annotations

import numpy as np

from simdiff.motion import quaternion as Q
from simdiff.motion.skeleton import FACE_JOINTS, KINEMATIC_CHAIN, NUM_JOINTS, RAW_OFFSETS

UP = np.array([0.0, 1.0, 0.0])
FORWARD = np.array([0.0, 0.0, 1.0])


def facing_direction(
    joints: np.ndarray, face_joints: tuple[int, int, int, int], *, smooth_sigma: float = 0.0
) -> np.ndarray:
    """Unit horizontal facing direction per frame.

    Args:
        joints: (T, 22, 3) positions.
        face_joints: (a, b, c, d); across = (j[a] - j[b]) + (j[c] - j[d]),
            forward = up × across.
        smooth_sigma: if > 0, Gaussian-smooth forward over time (σ in frames) before
            normalising it.
    Returns:
        (T, 3) unit vectors in the XZ plane.
    """
    a, b, c, d = face_joints
    across = (joints[:, a] - joints[:, b]) + (joints[:, c] - joints[:, d])
    across = across / np.linalg.norm(across, axis=-1, keepdims=True)
    forward = np.cross(UP, across)
    if smooth_sigma > 0:
        from scipy.ndimage import gaussian_filter1d  # lazy: scipy.ndimage costs ~0.3 s to import

        forward = gaussian_filter1d(forward, smooth_sigma, axis=0, mode="nearest")
    return forward / np.linalg.norm(forward, axis=-1, keepdims=True)


def inverse_kinematics(
    joints: np.ndarray,
    *,
    smooth_forward: bool = False,
    hip_quirk: bool = True,
    face_joints: tuple[int, int, int, int] = FACE_JOINTS,
) -> np.ndarray:
    """Local joint quaternions that pose the raw-offset skeleton like ``joints``.

    Args:
        joints: (T, 22, 3) positions in metres.
        smooth_forward: Gaussian-smooth the facing direction over time (σ = 20 frames),
            as HumanML3D does for the feature's root rotation.
        hip_quirk: reproduce HumanML3D's original index mix-up, which reads the face
            joints as (l_hip, r_hip, r_sdr, l_sdr): the hip "across" vector is then
            reversed relative to the shoulder one. Needed to match the shipped data.
        face_joints: (r_hip, l_hip, r_shoulder, l_shoulder).
    Returns:
        (T, 22, 4) quaternions; joint 0 is the root rotation (world → facing +Z), set to
        identity at frame 0 as MDM's skeleton code does.
    """
    joints = np.asarray(joints, dtype=np.float64)
    r_hip, l_hip, r_sdr, l_sdr = face_joints
    if hip_quirk:
        order = (l_hip, r_hip, r_sdr, l_sdr)
    else:
        order = (r_hip, l_hip, r_sdr, l_sdr)
    forward = facing_direction(joints, order, smooth_sigma=20.0 if smooth_forward else 0.0)
    root = Q.qbetween(forward, np.broadcast_to(FORWARD, forward.shape))
    root[0] = (1.0, 0.0, 0.0, 0.0)

    n = joints.shape[0]
    quats = np.zeros((n, NUM_JOINTS, 4))
    quats[..., 0] = 1.0
    quats[:, 0] = root
    for chain in KINEMATIC_CHAIN:
        acc = root
        for parent, child in zip(chain[:-1], chain[1:]):
            rest = np.broadcast_to(RAW_OFFSETS[child], (n, 3))
            bone = joints[:, child] - joints[:, parent]
            bone = bone / np.linalg.norm(bone, axis=-1, keepdims=True)
            local = Q.qmul(Q.qinv(acc), Q.qbetween(rest, bone))
            quats[:, child] = local
            acc = Q.qmul(acc, local)
    return quats


def forward_kinematics(quats: np.ndarray, root_pos: np.ndarray, offsets: np.ndarray) -> np.ndarray:
    """Joint positions from local quaternions.

    Args:
        quats: (T, 22, 4) local rotations as returned by :func:`inverse_kinematics`.
        root_pos: (T, 3) pelvis positions in metres.
        offsets: (22, 3) or (T, 22, 3) rest offsets of each joint from its parent.
    Returns:
        (T, 22, 3) positions in metres.
    """
    n = quats.shape[0]
    offsets = np.broadcast_to(np.asarray(offsets, dtype=np.float64), (n, NUM_JOINTS, 3))
    joints = np.zeros((n, NUM_JOINTS, 3))
    joints[:, 0] = root_pos
    for chain in KINEMATIC_CHAIN:
        acc = quats[:, 0]
        for parent, child in zip(chain[:-1], chain[1:]):
            acc = Q.qmul(acc, quats[:, child])
            joints[:, child] = Q.qrot(acc, offsets[:, child]) + joints[:, parent]
    return joints


def forward_kinematics_matrix(rots: np.ndarray, root_pos: np.ndarray, offsets: np.ndarray) -> np.ndarray:
    """Like :func:`forward_kinematics` with (T, 22, 3, 3) local rotation matrices."""
    n = rots.shape[0]
    offsets = np.broadcast_to(np.asarray(offsets, dtype=np.float64), (n, NUM_JOINTS, 3))
    joints = np.zeros((n, NUM_JOINTS, 3))
    joints[:, 0] = root_pos
    for chain in KINEMATIC_CHAIN:
        acc = rots[:, 0]
        for parent, child in zip(chain[:-1], chain[1:]):
            acc = acc @ rots[:, child]
            joints[:, child] = np.einsum("tij,tj->ti", acc, offsets[:, child]) + joints[:, parent]
    return joints
