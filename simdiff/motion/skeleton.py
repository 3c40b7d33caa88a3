"""The HumanML3D 22-joint skeleton: names, kinematic chain, raw offsets, canonical bones.

Coordinates are metres, Y-up; a character at frame 0 faces +Z and its left is +X.
"""

from __future__ import annotations

import numpy as np

FPS: int = 20
"""HumanML3D frame rate (frames per second)."""

NUM_JOINTS: int = 22
MAX_FRAMES: int = 196
"""Longest motion MDM handles (9.8 s at 20 fps)."""

MIN_FRAMES: int = 40
"""Shortest clip kept by MDM's loader (2 s)."""

MIN_GENERATE_FRAMES: int = 10
"""Shortest motion ``generate``, ``sample`` and the viewer make (0.5 s): the features' velocities, the foot cleanup
and the BVH need several frames, and the model saw no clip shorter than :data:`MIN_FRAMES`."""

JOINT_NAMES: tuple[str, ...] = (
    "pelvis", "left_hip", "right_hip", "spine1", "left_knee", "right_knee", "spine2",
    "left_ankle", "right_ankle", "spine3", "left_foot", "right_foot", "neck",
    "left_collar", "right_collar", "head", "left_shoulder", "right_shoulder",
    "left_elbow", "right_elbow", "left_wrist", "right_wrist",
)

KINEMATIC_CHAIN: tuple[tuple[int, ...], ...] = (
    (0, 2, 5, 8, 11),  # right leg
    (0, 1, 4, 7, 10),  # left leg
    (0, 3, 6, 9, 12, 15),  # spine to head
    (9, 14, 17, 19, 21),  # right arm
    (9, 13, 16, 18, 20),  # left arm
)


def _parents() -> tuple[int, ...]:
    parents = [-1] * NUM_JOINTS
    for chain in KINEMATIC_CHAIN:
        for parent, child in zip(chain[:-1], chain[1:]):
            parents[child] = parent
    return tuple(parents)


PARENTS: tuple[int, ...] = _parents()
"""Parent index of every joint (-1 for the pelvis)."""

RAW_OFFSETS: np.ndarray = np.array(
    [
        [0, 0, 0], [1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, -1, 0], [0, 1, 0],
        [0, -1, 0], [0, -1, 0], [0, 1, 0], [0, 0, 1], [0, 0, 1], [0, 1, 0], [1, 0, 0],
        [-1, 0, 0], [0, 0, 1], [0, -1, 0], [0, -1, 0], [0, -1, 0], [0, -1, 0], [0, -1, 0],
        [0, -1, 0],
    ],
    dtype=np.float64,
)
"""(22, 3) unit rest directions of each bone (HumanML3D T-pose convention, not SMPL's)."""

BONE_LENGTHS: np.ndarray = np.array(
    [
        0.0, 0.10307396, 0.109883465, 0.13156833, 0.3936233, 0.3901882, 0.14319032,
        0.4324335, 0.42564377, 0.05736474, 0.14338163, 0.14941914, 0.21936023,
        0.13748689, 0.14338295, 0.10303912, 0.13161407, 0.122984216, 0.25683978,
        0.26309198, 0.2660116, 0.2698759,
    ],
    dtype=np.float64,
)
"""(22,) canonical length in metres of the bone from each joint's parent to it.

Every HumanML3D clip is retargeted to these (measured, float32 precision, from a shipped
HumanML3D clip; they are constant over frames and clips)."""

CANONICAL_OFFSETS: np.ndarray = RAW_OFFSETS * BONE_LENGTHS[:, None]
"""(22, 3) rest-pose offsets in metres of each joint from its parent."""

FOOT_LEFT: tuple[int, int] = (7, 10)
"""Left ankle and left foot (toe) joints; contact channels 259, 260."""
FOOT_RIGHT: tuple[int, int] = (8, 11)
"""Right ankle and right foot (toe) joints; contact channels 261, 262."""
FACE_JOINTS: tuple[int, int, int, int] = (2, 1, 17, 16)
"""(r_hip, l_hip, r_shoulder, l_shoulder), used to find the facing direction."""
LEG_JOINTS: tuple[int, int] = (5, 8)
"""Knee and ankle whose offsets define the leg length for root scaling."""

LOWER_BODY: tuple[int, ...] = (0, 1, 2, 4, 5, 7, 8, 10, 11)
"""Pelvis, hips, knees, ankles and feet."""
UPPER_BODY: tuple[int, ...] = (0, 3, 6, 9, 12, 13, 14, 15, 16, 17, 18, 19, 20, 21)
"""Pelvis, spine, neck, head, collars and arms (the pelvis carries both halves)."""
RIGHT_CHAIN: tuple[int, ...] = (2, 5, 8, 11, 14, 17, 19, 21)
LEFT_CHAIN: tuple[int, ...] = (1, 4, 7, 10, 13, 16, 18, 20)


def mirror_permutation() -> np.ndarray:
    """(22,) index array that swaps left and right joints."""
    perm = np.arange(NUM_JOINTS)
    perm[list(RIGHT_CHAIN)] = LEFT_CHAIN
    perm[list(LEFT_CHAIN)] = RIGHT_CHAIN
    return perm


def bone_offsets(joints: np.ndarray) -> np.ndarray:
    """Offsets ``raw_direction * |joint - parent|`` of one pose.

    Args:
        joints: (22, 3) positions in metres.
    Returns:
        (22, 3) offsets; row 0 is zero.
    """
    joints = np.asarray(joints, dtype=np.float64)
    lengths = np.zeros(NUM_JOINTS)
    idx = np.arange(1, NUM_JOINTS)
    lengths[1:] = np.linalg.norm(joints[idx] - joints[np.asarray(PARENTS)[idx]], axis=-1)
    return RAW_OFFSETS * lengths[:, None]
