"""Rig descriptions shared by the retargeter: joint-map entries and :class:`RigSpec`."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from simdiff.motion.io.rig import RigMotion

Source = str | tuple[str, str, float] | tuple[tuple[str, float], ...]
"""A joint name; ``(a, b, t)``: the point ``a + t * (b - a)``; or ``((name, weight), ...)``:
a weighted mean of joints (weights summing to 1)."""

BvhSite = tuple[str, str, str, tuple[float, float, float]]
"""``(name, joint, child, (left, up, forward))``: a point rigid with BVH ``joint``'s frame
(the frame that places ``child``), at ``child``'s rest position plus the offset in units of
the rest bone length ``|child - joint|`` (when ``child == joint``: of the joint's own bone,
from its parent) along the rig's rest-pose axes (:attr:`RigSpec.rest_axes`)."""


def terms(src: Source) -> tuple[tuple[str, float], ...]:
    """A map entry as (joint name, weight) pairs."""
    if isinstance(src, str):
        return ((src, 1.0),)
    if len(src) == 3 and isinstance(src[0], str):
        a, b, t = src  # type: ignore[misc]
        return ((a, 1.0 - float(t)), (b, float(t)))  # type: ignore[return-value]
    return tuple((str(n), float(w)) for n, w in src)  # type: ignore[misc]


def sources_of(src: Source) -> set[str]:
    """Joint names a map entry reads."""
    return {name for name, _ in terms(src)}


@dataclass(frozen=True)
class RigSpec:
    """One source rig family.

    Attributes:
        name: short id ("cmu_asf", "bandai", ...), stored in ``RigMotion.meta["rig"]``.
        joint_map: HumanML3D joint -> :data:`Source` (toes may be left out: derived).
        required: joint names that identify the rig (default: every name the map reads).
        units: metres per BVH file unit when the rig's unit is known (None: detect).
        rest_axes: (left, up, forward) unit vectors of the BVH rest pose (all rotations 0)
            in file axes, for :data:`BvhSite` offsets.
        bvh_sites: derived BVH points the map reads (added by the BVH reader).
        first_frame_tpose: every file starts with an added T-pose frame (dropped on reading).
        prepare: fixes the rig positions before mapping (e.g. a missing bone), or None.
        finish: clean-up of the retargeted (T, 22, 3) joints at ``fps`` (floor at 0), or None.
    """

    name: str
    joint_map: dict[str, Source]
    required: frozenset[str] | None = None
    units: float | None = None
    rest_axes: tuple[tuple[float, float, float], ...] = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
    bvh_sites: tuple[BvhSite, ...] = ()
    first_frame_tpose: bool = False
    prepare: Callable[[RigMotion], RigMotion] | None = None
    finish: Callable[[np.ndarray, float], np.ndarray] | None = None

    def needs(self) -> frozenset[str]:
        """Joint names that must be present for this rig to match (before sites are added)."""
        if self.required is not None:
            return self.required
        sites = {s[0] for s in self.bvh_sites}
        names: set[str] = set()
        for src in self.joint_map.values():
            names |= sources_of(src)
        return frozenset(names - sites)

    def matches(self, names: tuple[str, ...] | set[str]) -> bool:
        """Whether a rig with these joint names is this family."""
        return self.needs() <= set(names)
