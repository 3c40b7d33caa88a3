"""Character-Creator BVH rig (``CC_Base_*``, the CMU BVH set of ``../cmu/bvh.tar.xz``)."""

from __future__ import annotations

from simdiff.motion.io.rigs.base import RigSpec, Source

_CC_S2, _CC_NECK = "CC_Base_Spine02", "CC_Base_NeckTwist01"
_CC_LT, _CC_RT = "CC_Base_L_Thigh", "CC_Base_R_Thigh"
_CC_HEAD, _CC_JAW, _CC_LEYE, _CC_REYE = "CC_Base_Head", "CC_Base_JawRoot", "CC_Base_L_Eye", "CC_Base_R_Eye"


def _chest_forward(weight: float) -> tuple[tuple[str, float], ...]:
    """``weight`` x the CC chest's forward vector (breast minus ribs joint, ~3 cm, both sides):
    terms summing to 0, to add to a map entry."""
    h = weight / 2
    return (("CC_Base_L_Breast", h), ("CC_Base_L_RibsTwist", -h),
            ("CC_Base_R_Breast", h), ("CC_Base_R_RibsTwist", -h))


CC_BVH_MAP: dict[str, Source] = {
    # pelvis 15 % of the way from the hip centre to the neck (as CMU_ASF_MAP)
    "pelvis": ((_CC_LT, 0.425), (_CC_RT, 0.425), (_CC_NECK, 0.15)),
    "left_hip": _CC_LT,
    "right_hip": _CC_RT,
    # the CC spine joints run 4-6 cm in front of the hip-neck line (belly side); spine1/2/3
    # are moved back along the chest's forward vector to SMPL's place (see CMU_ASF_MAP)
    "spine1": ((_CC_S2, 0.646), (_CC_LT, 0.177), (_CC_RT, 0.177), *_chest_forward(-1.08)),
    "left_knee": "CC_Base_L_Calf",
    "right_knee": "CC_Base_R_Calf",
    "spine2": ((_CC_S2, 0.9), (_CC_NECK, 0.1), *_chest_forward(-0.99)),
    "left_ankle": "CC_Base_L_Foot",
    "right_ankle": "CC_Base_R_Foot",
    "spine3": ((_CC_S2, 0.736), (_CC_NECK, 0.264), *_chest_forward(-0.26)),
    "left_foot": "CC_Base_L_ToeBase",
    "right_foot": "CC_Base_R_ToeBase",
    "neck": _CC_NECK,
    # collar: 0.45 of the way from the chest top (0.6 of Spine02 -> neck) to the shoulder
    "left_collar": ((_CC_S2, 0.22), (_CC_NECK, 0.33), ("CC_Base_L_Upperarm", 0.45)),
    "right_collar": ((_CC_S2, 0.22), (_CC_NECK, 0.33), ("CC_Base_R_Upperarm", 0.45)),
    # SMPL head joint (skull centre, low): a rigid point of the CC head given by its
    # landmarks (head joint, eyes, jaw root); CC_Base_Head alone sits at the top of the
    # neck, 3 cm too far back
    "head": ((_CC_HEAD, -1.69), (_CC_LEYE, -0.325), (_CC_REYE, -0.325), (_CC_JAW, 3.34)),
    "left_shoulder": "CC_Base_L_Upperarm",
    "right_shoulder": "CC_Base_R_Upperarm",
    "left_elbow": "CC_Base_L_Forearm",
    "right_elbow": "CC_Base_R_Forearm",
    "left_wrist": "CC_Base_L_Hand",
    "right_wrist": "CC_Base_R_Hand",
}
"""Reallusion Character-Creator rig (the CMU BVH set) -> HumanML3D joints, placed at the
same anatomical (SMPL) points as :data:`CMU_ASF_MAP`, measured on BVH trials that have no
AMC version (so the 22 AMC/BVH trials stay a cross-check)."""

CC_BVH: RigSpec = RigSpec("cc_bvh", CC_BVH_MAP)
