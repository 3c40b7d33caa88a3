"""Generic BVH biped names (Mixamo/LAFAN/cgspeed-style ``Hips``, ``LeftUpLeg``, ...)."""

from __future__ import annotations

from simdiff.motion.io.rigs.base import Source

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


def biped_map(names: tuple[str, ...]) -> dict[str, Source] | None:
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
