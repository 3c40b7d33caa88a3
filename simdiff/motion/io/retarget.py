"""Retarget source-rig joint positions to the 22-joint HumanML3D skeleton.

Each supported rig has a joint map: every HumanML3D joint is one source joint or a point
on the segment between two (``lerp``), which places spine, collar, neck and toe joints
where a rig lacks them. Output is (T, 22, 3) float32 metres, Y-up, at 20 fps, with the
floor (lowest joint over the clip) at y = 0 as in HumanML3D.

Supported rigs (maps and per-rig clean-up in :mod:`simdiff.motion.io.rigs`): CMU ASF/AMC
(31 bones; also HDM05), CMU Motionbuilder BVH, the Character-Creator BVH rig (``CC_Base_*``),
Daz-style CMU BVH, Bandai-Namco BVH, the DeepMimic humanoid3d (with its derived toe/neck/head
sites; :func:`retarget_rig` applies its ground clean-up ``lift_penetrations``), common BVH
biped names (Mixamo/LAFAN/cgspeed-style ``Hips``, ``LeftUpLeg``, ...) and files already on
the HumanML3D joints (e.g. written by :func:`simdiff.motion.io.write_bvh`).
"""

from __future__ import annotations

import numpy as np

from simdiff.errors import MotionFormatError
from simdiff.motion.io.resample import resample
from simdiff.motion.io.rig import RigMotion
from simdiff.motion.skeleton import BONE_LENGTHS, FPS, JOINT_NAMES, NUM_JOINTS, PARENTS
from simdiff.motion.io.rigs import (  # noqa: F401  (re-exported: the joint maps are importable from here too)
    BANDAI_MAP,
    CC_BVH_MAP,
    CMU_ASF_MAP,
    CMU_MB_MAP,
    DAZ_MAP,
    DEEPMIMIC_MAP,
    HUMANML3D_MAP,
    RigSpec,
    Source,
    detect_rig,
)
from simdiff.motion.io.rigs.base import terms as _terms


def joint_map_for(rig: RigMotion) -> dict[str, Source]:
    """The joint map that fits ``rig``'s joint names (see :func:`simdiff.motion.io.rigs.detect_rig`).

    Raises:
        MotionFormatError: when no known rig matches.
    """
    return rig_spec_for(rig).joint_map


def rig_spec_for(rig: RigMotion) -> RigSpec:
    """The rig family of ``rig``: ``rig.meta["rig"]`` when a reader set it, else detected."""
    spec = rig.meta.get("rig")
    if isinstance(spec, RigSpec):
        return spec
    return detect_rig(rig.names, rig.source)


def map_joints(rig: RigMotion, joint_map: dict[str, Source] | None = None) -> np.ndarray:
    """Apply a joint map: (T, 22, 3) float64 positions in the rig's frame and frame rate.

    A map may leave out the toe joints ("left_foot", "right_foot"); they are then derived
    from the ankle (:func:`derive_toes`).
    """
    joint_map = joint_map if joint_map is not None else joint_map_for(rig)
    out = np.empty((rig.num_frames, NUM_JOINTS, 3))
    positions = rig.positions.astype(np.float64)
    for j, name in enumerate(JOINT_NAMES):
        if name in _TOES and name not in joint_map:
            continue
        out[:, j] = sum(w * positions[:, rig.index(n)] for n, w in _terms(joint_map[name]))
    for name in _TOES:
        if name not in joint_map:
            out[:, JOINT_NAMES.index(name)] = derive_toes(out)[name]
    return out


_TOES = ("left_foot", "right_foot")


def derive_toes(joints: np.ndarray) -> dict[str, np.ndarray]:
    """Toe (ball of foot) positions for rigs without toes, from the other joints.

    Each toe lies ahead of its ankle along the body's horizontal facing direction
    (``(left_hip - right_hip) x up``) by 0.33 x the shin length and 0.12 x it lower
    (0.14 m and 0.05 m for a 0.43 m shin, HumanML3D's ankle-to-toe proportions).

    Args:
        joints: (T, 22, 3) positions, metres, Y-up; hips, knees and ankles filled in.
    Returns:
        {"left_foot": (T, 3), "right_foot": (T, 3)}.
    """
    up = np.array([0.0, 1.0, 0.0])
    left = joints[:, 1] - joints[:, 2]
    forward = np.cross(left, up)
    forward[:, 1] = 0.0
    forward /= np.maximum(np.linalg.norm(forward, axis=-1, keepdims=True), 1e-9)
    toes = {}
    for name, knee, ankle in (("left_foot", 4, 7), ("right_foot", 5, 8)):
        shin = np.linalg.norm(joints[:, knee] - joints[:, ankle], axis=-1, keepdims=True)
        toes[name] = joints[:, ankle] + shin * (0.33 * forward - 0.12 * up)
    return toes


def put_on_floor(joints: np.ndarray) -> np.ndarray:
    """Shift (T, 22, 3) joints vertically so the lowest joint over the clip is at y = 0."""
    joints = np.array(joints, dtype=np.float64, copy=True)
    joints[..., 1] -= joints[..., 1].min()
    return joints


def to_canonical_lengths(joints: np.ndarray, *, floor: bool = True) -> np.ndarray:
    """Rebuild (T, 22, 3) joints with HumanML3D's canonical bone lengths.

    Bone directions are kept; the pelvis trajectory is scaled by canonical / source leg
    length (hip-knee-ankle, both sides), as HumanML3D does when it unifies skeletons.
    With ``floor`` the result is put on the floor.
    """
    joints = np.asarray(joints, dtype=np.float64)
    parents = np.asarray(PARENTS)
    leg_bones = [4, 7, 5, 8]  # hip -> knee, knee -> ankle, both sides
    src_leg = np.linalg.norm(joints[:, leg_bones] - joints[:, parents[leg_bones]], axis=-1).mean()
    dst_leg = BONE_LENGTHS[leg_bones].mean()
    out = np.empty_like(joints)
    out[:, 0] = joints[:, 0] * (dst_leg / max(src_leg, 1e-9))
    for j in range(1, NUM_JOINTS):
        p = parents[j]
        bone = joints[:, j] - joints[:, p]
        norm = np.linalg.norm(bone, axis=-1, keepdims=True)
        direction = np.divide(bone, norm, out=np.zeros_like(bone), where=norm > 1e-9)
        out[:, j] = out[:, p] + direction * BONE_LENGTHS[j]
    return put_on_floor(out) if floor else out


def retarget_rig(
    rig: RigMotion,
    *,
    fps: float = FPS,
    floor: bool = True,
    canonical: bool = False,
    joint_map: dict[str, Source] | None = None,
    clean: bool = True,
) -> np.ndarray:
    """Source rig motion -> HumanML3D joints.

    The rig family (:func:`rig_spec_for`) may fix the rig first (``prepare``: CMU
    Motionbuilder's thorax) and clean the result (``finish``: DeepMimic's
    ``lift_penetrations``, only with ``floor`` and not ``canonical``).

    Args:
        rig: positions on any supported rig (metres, Y-up).
        fps: output frame rate (HumanML3D: 20); resampled with an anti-alias filter.
        floor: shift so the lowest joint over the clip touches y = 0.
        canonical: also rebuild with HumanML3D's canonical bone lengths.
        joint_map: explicit map (default: chosen from the rig's joint names).
        clean: apply the family's ``prepare`` / ``finish`` steps.
    Returns:
        (T', 22, 3) float32 metres, Y-up.
    """
    spec: RigSpec | None = None
    try:
        spec = rig_spec_for(rig)
    except MotionFormatError:
        if joint_map is None:
            raise
    if spec is not None and clean and spec.prepare is not None:
        rig = spec.prepare(rig)
    joints = map_joints(rig, joint_map if joint_map is not None else spec.joint_map)  # type: ignore[union-attr]
    joints = resample(joints, rig.fps, fps).astype(np.float64)
    if canonical:
        joints = to_canonical_lengths(joints, floor=floor)
    elif floor:
        joints = put_on_floor(joints)
        if spec is not None and clean and spec.finish is not None:
            joints = spec.finish(joints, fps)
    return np.asarray(joints, dtype=np.float32)

