"""Daz-style BVH rig of the CMU conversions (43 joints: ``hip``, ``abdomen``, ``chest``,
``neck``, ``head``, eyes, collars, arms, fingers, ``rButtock``/``rThigh``/``rShin``/``rFoot``).

Centimetres, Y up, the rest pose faces +Z with the left side towards +X. The foot has no toe
joint: its End Site (12-13 cm ahead of and 4 cm below the ankle) is the ball of the foot.
"""

from __future__ import annotations

from simdiff.motion.io.ground import level_ground
from simdiff.motion.io.rigs.base import RigSpec, Source

DAZ_MAP: dict[str, Source] = {
    "pelvis": (("lThigh", 0.425), ("rThigh", 0.425), ("neck", 0.15)),
    "left_hip": "lThigh",
    "right_hip": "rThigh",
    "spine1": ("abdomen", "chest", 0.0),
    "left_knee": "lShin",
    "right_knee": "rShin",
    "spine2": ("chest", "neck", 0.0),
    "left_ankle": "lFoot",
    "right_ankle": "rFoot",
    "spine3": ("chest", "neck", 0.16),
    "left_foot": "lFoot_End",
    "right_foot": "rFoot_End",
    "neck": "neck",
    # collar 0.45 of the way from the trunk line at 0.8 up to the shoulder (CMU_ASF_MAP)
    "left_collar": (("chest", 0.25), ("neck", 0.30), ("lShldr", 0.45)),
    "right_collar": (("chest", 0.25), ("neck", 0.30), ("rShldr", 0.45)),
    "head": "head_centre",
    "left_shoulder": "lShldr",
    "right_shoulder": "rShldr",
    "left_elbow": "lForeArm",
    "right_elbow": "rForeArm",
    "left_wrist": "lHand",
    "right_wrist": "rHand",
}
"""Daz joints -> HumanML3D joints (placement: docs/corpus.md)."""

DAZ: RigSpec = RigSpec(
    "daz",
    DAZ_MAP,
    units=0.01,
    # SMPL head: 2.8 cm in front of and 0.5 cm below the head joint (top of the neck), in
    # units of the 7.18 cm neck bone
    bvh_sites=(("head_centre", "head", "head", (0.0, -0.070, 0.390)),),
    finish=level_ground,
)
"""CMU Daz-style BVH (also the acLSTM dance folders), centimetres."""
