"""Bandai-Namco Research Motiondataset BVH rig (22 joints, centimetres, 30 fps).

Hierarchy: static ``joint_Root`` (on the floor) -> ``Hips`` -> ``Spine`` -> ``Chest`` ->
``Neck`` -> ``Head``; ``Chest`` -> ``Shoulder_L/R`` (clavicle) -> ``UpperArm`` -> ``LowerArm``
-> ``Hand``; ``Hips`` -> ``UpperLeg_L/R`` -> ``LowerLeg`` -> ``Foot`` -> ``Toes`` (ball of the
foot; the End Sites have zero length). Every joint has 6 channels. In the rest pose (all
rotations 0) the spine runs along +X, the character's left is +Z, so it faces +Y; the
animation itself is Y-up and faces +Z.
"""

from __future__ import annotations

from simdiff.motion.io.rigs.base import RigSpec, Source

_HL, _HR, _NECK, _SPINE, _CHEST = "UpperLeg_L", "UpperLeg_R", "Neck", "Spine", "Chest"

BANDAI_MAP: dict[str, Source] = {
    # pelvis 15 % of the way from the hip centre to the neck base (as CMU_ASF_MAP)
    "pelvis": ((_HL, 0.425), (_HR, 0.425), (_NECK, 0.15)),
    "left_hip": _HL,
    "right_hip": _HR,
    # spine1/2/3 at 0.335/0.565/0.64 of hip centre -> neck (SMPL); Spine sits at 0.414,
    # Chest at 0.622 of that line (measured, upright frames)
    "spine1": ((_SPINE, 0.809), (_HL, 0.0955), (_HR, 0.0955)),
    "left_knee": "LowerLeg_L",
    "right_knee": "LowerLeg_R",
    "spine2": (_SPINE, _CHEST, 0.726),
    "left_ankle": "Foot_L",
    "right_ankle": "Foot_R",
    "spine3": (_CHEST, _NECK, 0.05),
    "left_foot": "Toes_L",
    "right_foot": "Toes_R",
    "neck": _NECK,
    # collar 0.45 of the way from the trunk line at 0.78 up to the shoulder (CMU_ASF_MAP)
    "left_collar": ((_CHEST, 0.319), (_NECK, 0.231), ("UpperArm_L", 0.45)),
    "right_collar": ((_CHEST, 0.319), (_NECK, 0.231), ("UpperArm_R", 0.45)),
    "head": "head_centre",
    "left_shoulder": "UpperArm_L",
    "right_shoulder": "UpperArm_R",
    "left_elbow": "LowerArm_L",
    "right_elbow": "LowerArm_R",
    "left_wrist": "Hand_L",
    "right_wrist": "Hand_R",
}
"""Bandai-Namco joints -> HumanML3D joints (placement: docs/corpus.md)."""

BANDAI: RigSpec = RigSpec(
    "bandai",
    BANDAI_MAP,
    units=0.01,
    # rest pose: left +Z, up +X (spine), forward = left x up = +Y
    rest_axes=((0.0, 0.0, 1.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0)),
    # SMPL head: 3.7 cm in front of and 1.3 cm below the Head joint (top of the neck), in
    # units of the 6.46 cm neck bone
    bvh_sites=(("head_centre", "Head", "Head", (0.0, -0.201, 0.573)),),
)
"""Bandai-Namco BVH: centimetres (stated by the dataset; standing heights 1.5-1.8 m)."""
