"""Source rig families and their detection.

Each family is a :class:`RigSpec` (joint map to HumanML3D, known BVH units, derived sites,
optional clean-up before mapping / after retargeting), one module per family:

- ``cmu``: CMU ASF/AMC (31 bones; HDM05 uses the same bone names), the CMU
  "Motionbuilder-friendly" BVH and the CMU BVH named after the ASF bones (both drop the
  thorax bone: it is restored; the floor tilt is levelled);
- ``cc``: the Character-Creator BVH rig (``CC_Base_*``);
- ``deepmimic``: DeepMimic humanoid3d (:func:`simdiff.motion.io.ground.lift_penetrations`
  after retargeting);
- ``bandai``: Bandai-Namco game rig (centimetres);
- ``daz``: Daz-style CMU BVH (centimetres);
- ``biped``: common BVH biped names, a fallback map built from the names present.

:func:`detect_rig` returns the first family of :data:`RIGS` whose joints are all present.
"""

from __future__ import annotations

from simdiff.errors import MotionFormatError
from simdiff.motion.io.rigs.bandai import BANDAI, BANDAI_MAP
from simdiff.motion.io.rigs.base import BvhSite, RigSpec, Source, sources_of, terms
from simdiff.motion.io.rigs.biped import biped_map
from simdiff.motion.io.rigs.cc import CC_BVH, CC_BVH_MAP
from simdiff.motion.io.rigs.cmu import CMU_ASF, CMU_ASF_MAP, CMU_ASFBVH, CMU_MB, CMU_MB_MAP
from simdiff.motion.io.rigs.daz import DAZ, DAZ_MAP
from simdiff.motion.io.rigs.deepmimic import DEEPMIMIC, DEEPMIMIC_MAP
from simdiff.motion.skeleton import JOINT_NAMES

__all__ = [
    "BANDAI", "BANDAI_MAP", "CC_BVH", "CMU_ASFBVH", "CC_BVH_MAP", "CMU_ASF", "CMU_ASF_MAP", "CMU_MB",
    "CMU_MB_MAP", "DAZ", "DAZ_MAP", "DEEPMIMIC", "DEEPMIMIC_MAP", "HUMANML3D", "HUMANML3D_MAP",
    "RIGS", "BvhSite", "RigSpec", "Source", "detect_rig", "sources_of", "terms",
]

HUMANML3D_MAP: dict[str, Source] = {name: name for name in JOINT_NAMES}
"""Identity map for rigs already named like HumanML3D (e.g. our own BVH writer)."""
HUMANML3D: RigSpec = RigSpec("humanml3d", HUMANML3D_MAP)

RIGS: tuple[RigSpec, ...] = (HUMANML3D, CMU_ASF, CC_BVH, DEEPMIMIC, CMU_MB, CMU_ASFBVH, BANDAI, DAZ)
"""Known families, in detection order (the generic biped map comes last)."""


def detect_rig(names: tuple[str, ...], source: object = None) -> RigSpec:
    """The rig family of a skeleton with these joint names.

    Args:
        names: the rig's joint names (BVH: before derived sites are added).
        source: the file, for the error message.
    Raises:
        MotionFormatError: when no family and no biped naming matches.
    """
    for spec in RIGS:
        if spec.matches(names):
            return spec
    biped = biped_map(tuple(names))
    if biped is not None:
        return RigSpec("biped", biped)
    sample = ", ".join(names[:6])
    raise MotionFormatError(
        source or "<motion>", f"no HumanML3D joint map for this rig ({len(names)} joints: {sample}, ...)"
    )
