"""Flight phases of a clip: frames where both feet (and every other joint) are off the floor.

Computed on ``new_joints`` (T, 22, 3), metres, Y-up, 20 fps. Heights are measured from the
clip's ground: the :data:`GROUND_PERCENTILE` th percentile of the per-frame lowest joint (the
stored floor, the lowest joint of the clip, can be set by one glitch frame: a CMU dance with a
single dipping toe then "flies" for 8 s). A foot is off the floor when its ankle is above
:data:`ANKLE_HEIGHT` **and** its
toe above :data:`TOE_HEIGHT` (standing, the canonical ankle is ~8 cm and the toe ~0-2 cm up;
HumanML3D's contact labels use similar heights); a frame is airborne when both feet are off
and no other joint is below :data:`TOE_HEIGHT` (a handstand or a roll is not flight). Height
only, no velocity: a jump's apex is slow but airborne. Clips whose floor is wrong (floating
props, hanging) can count as flying: the report names the longest flights to check them.
"""

from __future__ import annotations

import numpy as np

from simdiff.motion.skeleton import FPS

ANKLE_HEIGHT: float = 0.10
"""Ankle height (m) above the floor beyond which that foot may be off the ground."""
TOE_HEIGHT: float = 0.05
"""Toe (and any non-foot joint) height (m) beyond which it is off the ground."""
GROUND_PERCENTILE: float = 5.0
"""Percentile of the per-frame lowest joint taken as the ground."""
MIN_FLIGHT_S: float = 0.2
"""A flight phase this long (s) or longer marks the clip as having real flight."""

_ANKLES, _TOES = (7, 8), (10, 11)


def airborne(joints: np.ndarray) -> np.ndarray:
    """(T,) bool: both feet and every other joint off the floor (see module docstring)."""
    y = np.asarray(joints, dtype=np.float64)[..., 1]
    if y.shape[0]:
        y = y - np.percentile(y.min(axis=1), GROUND_PERCENTILE)
    feet_off = np.all(y[:, list(_ANKLES)] > ANKLE_HEIGHT, axis=1) & np.all(y[:, list(_TOES)] > TOE_HEIGHT, axis=1)
    others = [j for j in range(y.shape[1]) if j not in _ANKLES + _TOES]
    return feet_off & np.all(y[:, others] > TOE_HEIGHT, axis=1)


def flight_stats(joints: np.ndarray, fps: float = FPS) -> dict[str, float]:
    """Total airborne time and the longest airborne run of one clip, in seconds."""
    air = airborne(joints)
    longest = run = 0
    for flag in air:
        run = run + 1 if flag else 0
        longest = max(longest, run)
    return {"flight_s": float(air.sum() / fps), "longest_flight_s": float(longest / fps)}
