"""Retarget source-rig joint positions to the 22-joint HumanML3D skeleton.

Each supported rig has a joint map: every HumanML3D joint is one source joint or a point
on the segment between two (``lerp``), which places spine, collar, neck and toe joints
where a rig lacks them. Output is (T, 22, 3) float32 metres, Y-up, at 20 fps, with the
floor (lowest joint over the clip) at y = 0 as in HumanML3D.

Supported rigs: CMU ASF/AMC (31 bones), the Character-Creator BVH rig (``CC_Base_*``),
the DeepMimic humanoid3d (with its derived toe/neck/head sites), common BVH biped names
(Mixamo/LAFAN/cgspeed-style ``Hips``, ``LeftUpLeg``, ...) and files already on the
HumanML3D joints (e.g. written by :func:`simdiff.motion.io.write_bvh`).
"""

from __future__ import annotations

import numpy as np

from simdiff.errors import MotionFormatError
from simdiff.motion.io.resample import resample
from simdiff.motion.io.rig import RigMotion
from simdiff.motion.skeleton import BONE_LENGTHS, FPS, JOINT_NAMES, NUM_JOINTS, PARENTS

Source = str | tuple[str, str, float] | tuple[tuple[str, float], ...]
"""A joint name; ``(a, b, t)``: the point ``a + t * (b - a)``; or ``((name, weight), ...)``:
a weighted mean of joints (weights summing to 1)."""

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

Placement (pipeline v3) follows SMPL anatomy, measured in the trunk frame (hip centre ->
neck base = 1, upright frames): pelvis 0.15 up on that line; spine1/2/3 at 0.33/0.56/0.64
up and within 0.02-0.03 of the line (joints just in front of the vertebrae); head 0.12 above
and 0.095 in front of the neck base; shoulders level with the line. See
``reports/corpus/NOTES.md``."""

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

DEEPMIMIC_MAP: dict[str, Source] = {
    "pelvis": "root",
    "left_hip": "left_hip",
    "right_hip": "right_hip",
    "spine1": ("root", "chest", 0.5),
    "left_knee": "left_knee",
    "right_knee": "right_knee",
    "spine2": "chest",
    "left_ankle": "left_ankle",
    "right_ankle": "right_ankle",
    "spine3": ("chest", "neck", 0.25),
    "left_foot": "left_toe",
    "right_foot": "right_toe",
    "neck": "neck_top",
    "left_collar": ("neck", "left_shoulder", 0.45),
    "right_collar": ("neck", "right_shoulder", 0.45),
    "head": "head",
    "left_shoulder": "left_shoulder",
    "right_shoulder": "right_shoulder",
    "left_elbow": "left_elbow",
    "right_elbow": "right_elbow",
    "left_wrist": "left_wrist",
    "right_wrist": "right_wrist",
}
"""DeepMimic humanoid3d links and derived sites -> HumanML3D joints."""

HUMANML3D_MAP: dict[str, Source] = {name: name for name in JOINT_NAMES}
"""Identity map for rigs already named like HumanML3D (e.g. our own BVH writer)."""

_BIPED_CANDIDATES: dict[str, tuple[str, ...]] = {
    "pelvis": ("hips", "hip", "pelvis"),
    "left_hip": ("leftupleg", "leftthigh", "lthigh", "leftupperleg", "lefthip"),
    "right_hip": ("rightupleg", "rightthigh", "rthigh", "rightupperleg", "righthip"),
    "left_knee": ("leftleg", "leftshin", "lshin", "leftlowerleg", "leftknee"),
    "right_knee": ("rightleg", "rightshin", "rshin", "rightlowerleg", "rightknee"),
    "left_ankle": ("leftfoot", "lfoot", "leftankle"),
    "right_ankle": ("rightfoot", "rfoot", "rightankle"),
    "left_foot": ("lefttoebase", "lefttoe", "lefttoes", "ltoe"),
    "right_foot": ("righttoebase", "righttoe", "righttoes", "rtoe"),
    "neck": ("neck", "neck1"),
    "head": ("head",),
    "left_collar": ("leftshoulder", "leftcollar", "lcollar", "leftclavicle"),
    "right_collar": ("rightshoulder", "rightcollar", "rcollar", "rightclavicle"),
    "left_shoulder": ("leftarm", "leftupperarm", "lshldr", "leftuparm"),
    "right_shoulder": ("rightarm", "rightupperarm", "rshldr", "rightuparm"),
    "left_elbow": ("leftforearm", "leftlowerarm", "lforearm", "leftelbow"),
    "right_elbow": ("rightforearm", "rightlowerarm", "rforearm", "rightelbow"),
    "left_wrist": ("lefthand", "lhand", "leftwrist"),
    "right_wrist": ("righthand", "rhand", "rightwrist"),
}
_BIPED_SPINE = ("spine", "spine1", "spine2", "spine3", "chest", "upperchest")


def _normalise(name: str) -> str:
    """Lower-case, namespace prefix (``mixamorig:``) and separators removed."""
    name = name.rsplit(":", 1)[-1].rsplit("|", 1)[-1]
    return "".join(c for c in name.lower() if c.isalnum())


def _biped_map(names: tuple[str, ...]) -> dict[str, Source] | None:
    """Joint map for a BVH with common biped names, or None when joints are missing."""
    lookup = {}
    for name in names:
        lookup.setdefault(_normalise(name), name)
    out: dict[str, Source] = {}
    for target, candidates in _BIPED_CANDIDATES.items():
        found = next((lookup[c] for c in candidates if c in lookup), None)
        if found is not None:
            out[target] = found
    optional = ("left_foot", "right_foot", "left_collar", "right_collar")
    if any(t not in out for t in _BIPED_CANDIDATES if t not in optional):
        return None
    spine = [lookup[s] for s in _BIPED_SPINE if s in lookup]
    pelvis, neck = str(out["pelvis"]), str(out["neck"])
    # spine1..3 at the given spine joints, or at 0.25/0.5/0.6 of pelvis -> neck
    fallbacks = ((pelvis, neck, 0.25), (pelvis, neck, 0.5), (pelvis, neck, 0.6))
    for k, target in enumerate(("spine1", "spine2", "spine3")):
        out[target] = spine[k] if k < len(spine) else fallbacks[k]
    for side in ("left", "right"):
        if f"{side}_collar" not in out:
            out[f"{side}_collar"] = (neck, str(out[f"{side}_shoulder"]), 0.45)
    return out


def joint_map_for(rig: RigMotion) -> dict[str, Source]:
    """The joint map that fits ``rig``'s joint names.

    Raises:
        MotionFormatError: when no known rig matches.
    """
    names = set(rig.names)
    for candidate in (HUMANML3D_MAP, CMU_ASF_MAP, CC_BVH_MAP, DEEPMIMIC_MAP):
        if all(_sources_of(src) <= names for src in candidate.values()):
            return candidate
    biped = _biped_map(rig.names)
    if biped is not None:
        return biped
    sample = ", ".join(rig.names[:6])
    raise MotionFormatError(
        rig.source or "<motion>",
        f"no HumanML3D joint map for this rig ({len(rig.names)} joints: {sample}, ...)",
    )


def _terms(src: Source) -> tuple[tuple[str, float], ...]:
    """A map entry as (joint name, weight) pairs."""
    if isinstance(src, str):
        return ((src, 1.0),)
    if len(src) == 3 and isinstance(src[0], str):
        a, b, t = src  # type: ignore[misc]
        return ((a, 1.0 - float(t)), (b, float(t)))  # type: ignore[return-value]
    return tuple((str(n), float(w)) for n, w in src)  # type: ignore[misc]


def _sources_of(src: Source) -> set[str]:
    return {name for name, _ in _terms(src)}


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
) -> np.ndarray:
    """Source rig motion -> HumanML3D joints.

    Args:
        rig: positions on any supported rig (metres, Y-up).
        fps: output frame rate (HumanML3D: 20); resampled with an anti-alias filter.
        floor: shift so the lowest joint over the clip touches y = 0.
        canonical: also rebuild with HumanML3D's canonical bone lengths.
        joint_map: explicit map (default: chosen from the rig's joint names).
    Returns:
        (T', 22, 3) float32 metres, Y-up.
    """
    joints = map_joints(rig, joint_map)
    joints = resample(joints, rig.fps, fps).astype(np.float64)
    if canonical:
        joints = to_canonical_lengths(joints, floor=floor)
    elif floor:
        joints = put_on_floor(joints)
    return joints.astype(np.float32)

