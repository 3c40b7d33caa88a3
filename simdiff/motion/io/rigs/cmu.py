"""CMU skeletons: the 31-bone ASF/AMC rig (also HDM05's) and the "Motionbuilder-friendly" BVH
conversion of it (``Hips``, ``LHipJoint``, ``LeftUpLeg``, ..., ``LowerBack``, ``Spine``, ``Spine1``,
``Neck``, ``Neck1``, ``Head``)."""

from __future__ import annotations


from simdiff.motion.io.ground import level_ground
from simdiff.motion.io.rig import RigMotion
from simdiff.motion.io.rigs.base import RigSpec, Source, sources_of, terms

CMU_ASF_MAP: dict[str, Source] = {
    # pelvis: on the hip-centre -> neck-base line, 15 % of the way up (SMPL: ~9 cm above the
    # hip centres, in line with the trunk). CMU's root sits 2-4 cm behind the hip joints.
    "pelvis": (("lhipjoint", 0.425), ("rhipjoint", 0.425), ("lowerneck", 0.15)),
    "left_hip": "lhipjoint",
    "right_hip": "rhipjoint",
    # spine1/2/3 at 33 / 56 / 64 % of the hip-centre -> neck height (SMPL proportions)
    "spine1": (("lowerback", 0.825), ("lhipjoint", 0.0875), ("rhipjoint", 0.0875)),
    "left_knee": "lfemur",
    "right_knee": "rfemur",
    "spine2": ("upperback", "lowerback", 0.2),
    "left_ankle": "ltibia",
    "right_ankle": "rtibia",
    "spine3": ("upperback", "thorax", 0.2),
    "left_foot": "lfoot",
    "right_foot": "rfoot",
    "neck": "lowerneck",
    "left_collar": ("thorax", "lshoulder_centre", 0.45),
    "right_collar": ("thorax", "rshoulder_centre", 0.45),
    "head": "head_centre",
    "left_shoulder": "lshoulder_centre",
    "right_shoulder": "rshoulder_centre",
    "left_elbow": "lhumerus",
    "right_elbow": "rhumerus",
    "left_wrist": "lradius",
    "right_wrist": "rradius",
}
"""CMU ASF bone ends (a bone's joint is its end) and the reader's derived sites
(``head_centre``, ``l/rshoulder_centre``: :data:`simdiff.motion.io.asf_amc.ASF_SITES`)
-> HumanML3D joints.

Placement follows SMPL anatomy, measured in the trunk frame (hip centre ->
neck base = 1, upright frames): pelvis 0.15 up on that line; spine1/2/3 at 0.33/0.56/0.64
up and within 0.02-0.03 of the line (joints just in front of the vertebrae); head 0.12 above
and 0.095 in front of the neck base; shoulders level with the line. See ``docs/corpus.md``."""

CMU_ASF: RigSpec = RigSpec("cmu_asf", CMU_ASF_MAP)
"""CMU and HDM05 ASF/AMC (same bone names; the AMC reader adds the sites)."""

MB_FROM_ASF: dict[str, str] = {
    "lhipjoint": "LeftUpLeg", "rhipjoint": "RightUpLeg", "lowerback": "Spine",
    "upperback": "Spine1", "thorax": "Neck", "lowerneck": "Neck1", "upperneck": "Head",
    "head": "Head_End", "lfemur": "LeftLeg", "rfemur": "RightLeg", "ltibia": "LeftFoot",
    "rtibia": "RightFoot", "lfoot": "LeftToeBase", "rfoot": "RightToeBase",
    "lclavicle": "LeftArm", "rclavicle": "RightArm", "lhumerus": "LeftForeArm",
    "rhumerus": "RightForeArm", "lradius": "LeftHand", "rradius": "RightHand",
    "head_centre": "head_centre", "lshoulder_centre": "lshoulder_centre",
    "rshoulder_centre": "rshoulder_centre",
}
"""ASF bone (its end point) -> Motionbuilder BVH joint at the same place. The BVH joint
named after a bone sits at that bone's *start*, so each ASF bone end is the next joint."""


def _rename(src: Source) -> Source:
    return tuple((MB_FROM_ASF[n], w) for n, w in terms(src))


CMU_MB_MAP: dict[str, Source] = {k: _rename(v) for k, v in CMU_ASF_MAP.items()}
"""Motionbuilder BVH joints -> HumanML3D joints: :data:`CMU_ASF_MAP` with the joints renamed
(:data:`MB_FROM_ASF`), so the placement is the AMC one."""

THORAX_RATIO: float = 1.0
"""CMU thorax bone length / upperback length: 1.00-1.04 (median 1.005) over the 13 CMU ASF
files of ``../shared/data/cmu/asf``."""


def restore_thorax(rig: RigMotion, spine: str = "Spine", spine1: str = "Spine1") -> RigMotion:
    """Put back the CMU ``thorax`` bone that the Motionbuilder conversion drops.

    In these BVH files ``Neck`` has a zero OFFSET from ``Spine1`` (the ``upperback`` end)
    while every other bone matches the subject's ASF length, so neck, head and shoulders sit
    one thorax length (about 11 cm) too low. Everything above ``spine1`` is moved by
    :data:`THORAX_RATIO` x (spine1 - spine): the thorax continues the upperback's direction
    (both point straight up in the CMU rest pose).
    """
    top = rig.index(spine1)
    moved = [j for j in range(len(rig.names)) if _descends(rig.parents, j, top)]
    shift = THORAX_RATIO * (rig.positions[:, top] - rig.positions[:, rig.index(spine)])
    positions = rig.positions.copy()
    positions[:, moved] += shift[:, None]
    meta = dict(rig.meta, thorax_restored=True)
    return RigMotion(rig.names, rig.parents, positions, rig.fps, rig.source, meta)


def _descends(parents: tuple[int, ...], j: int, ancestor: int) -> bool:
    """Whether joint ``j`` lies strictly below ``ancestor``."""
    p = parents[j]
    while p >= 0:
        if p == ancestor:
            return True
        p = parents[p]
    return False


CMU_MB: RigSpec = RigSpec(
    "cmu_mb",
    CMU_MB_MAP,
    required=frozenset(set().union(*(sources_of(v) for v in CMU_MB_MAP.values()))
                       - {"head_centre", "lshoulder_centre", "rshoulder_centre"}
                       | {"LHipJoint", "LowerBack", "Neck1"}),
    units=0.0254 / 0.45,
    bvh_sites=(
        # the AMC reader's sites (asf_amc.ASF_SITES), on the same bones
        ("head_centre", "Head", "Head_End", (0.0, -1.26, 0.77)),
        ("lshoulder_centre", "LeftShoulder", "LeftArm", (0.0, -0.11, -0.14)),
        ("rshoulder_centre", "RightShoulder", "RightArm", (0.0, -0.11, -0.14)),
    ),
    first_frame_tpose=True,
    prepare=restore_thorax,
    finish=level_ground,
)
"""CMU Motionbuilder BVH: lengths in the CMU ASF unit (inch / 0.45), 120 fps, rest pose as
the ASF's (Y up, faces +Z, left +X); frame 0 is a T-pose (dropped by the reader)."""



ASFBVH_FROM_MB: dict[str, str] = {
    "LeftUpLeg": "lfemur", "RightUpLeg": "rfemur", "LeftLeg": "ltibia", "RightLeg": "rtibia",
    "LeftFoot": "lfoot", "RightFoot": "rfoot", "LeftToeBase": "ltoes", "RightToeBase": "rtoes",
    "Spine": "upperback", "Spine1": "thorax", "Neck": "lowerneck", "Neck1": "upperneck",
    "Head": "head", "Head_End": "head_End", "LeftShoulder": "lclavicle",
    "RightShoulder": "rclavicle", "LeftArm": "lhumerus", "RightArm": "rhumerus",
    "LeftForeArm": "lradius", "RightForeArm": "rradius", "LeftHand": "lwrist",
    "RightHand": "rwrist", "head_centre": "head_centre", "lshoulder_centre": "lshoulder_centre",
    "rshoulder_centre": "rshoulder_centre",
}
"""CMU Motionbuilder joint -> the same joint of the CMU BVH named after the ASF bones
(cgspeed-style ``hip``, ``lhipjoint``, ``lfemur``, ...: a joint named after a bone sits at
that bone's start; the thorax is dropped in the same way)."""

CMU_ASFBVH_MAP: dict[str, Source] = {
    k: tuple((ASFBVH_FROM_MB[n], w) for n, w in terms(v)) for k, v in CMU_MB_MAP.items()
}
"""ASF-named CMU BVH joints -> HumanML3D joints (:data:`CMU_MB_MAP` renamed)."""


def _restore_thorax_asfbvh(rig: RigMotion) -> RigMotion:
    return restore_thorax(rig, "upperback", "thorax")


CMU_ASFBVH: RigSpec = RigSpec(
    "cmu_asf_bvh",
    CMU_ASFBVH_MAP,
    required=frozenset({"hip", "lhipjoint", "lfemur", "ltibia", "lfoot", "ltoes", "lowerback",
                        "upperback", "thorax", "lowerneck", "upperneck", "head", "lclavicle",
                        "lhumerus", "lradius", "lwrist", "rclavicle", "rhumerus", "rradius",
                        "rwrist", "rfemur", "rtibia", "rfoot", "rtoes", "head_End"}),
    units=0.0254 / 0.45,
    bvh_sites=tuple((n, ASFBVH_FROM_MB[j], ASFBVH_FROM_MB[c], o) for n, j, c, o in CMU_MB.bvh_sites),
    prepare=_restore_thorax_asfbvh,
    finish=level_ground,
)
"""CMU BVH with ASF bone names (``daz/16_01.bvh`` of the extra set): as :data:`CMU_MB`."""
