"""Per-motion measurements of the model check: jumps, root speed, and the summaries over motions.

Input motions are joints (T, 22, 3), metres, Y-up, 20 fps (HumanML3D order, root = pelvis = joint 0).
Flight is the project's one offline rule (:mod:`simdiff.motion.flight`).

A motion **jumps** when it has a flight of at least :data:`MIN_FLIGHT_S` and, during that flight,
the pelvis rises at least :data:`MIN_RISE_M` above its *standing level*: the median pelvis height
over the frames outside every flight (the frames with a foot on the ground by the flight rule).
The median of the grounded frames is the stance height of a motion that mostly stands or walks;
a crouch before take-off lowers it a little (the rise is then slightly larger than over upright
stance), a motion that crouches throughout has its crouch as the level. A motion that never
touches the floor (:func:`simdiff.motion.metrics.never_touches`: its lowest joint stays above
0.10 m all clip long) does not jump, however its feet move relative to each other: it floats.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from scipy import stats as sps

from simdiff.errors import SimdiffError
from simdiff.motion.flight import MIN_FLIGHT_S, airborne, flights
from simdiff.motion.flight import check_joints as _joints
from simdiff.motion.metrics import never_touches
from simdiff.motion.skeleton import FPS

MIN_RISE_M: float = 0.15
"""Least pelvis rise above the standing level during that flight (m)."""


def standing_level(joints: np.ndarray) -> float:
    """Median pelvis height (m) over the frames outside every flight (NaN when every frame flies)."""
    j = _joints(joints)
    ground = ~airborne(j)
    return float(np.median(j[ground, 0, 1])) if ground.any() else float("nan")


def jump_stats(joints: np.ndarray, fps: float = FPS) -> dict[str, float | bool]:
    """Jump measurements of one motion.

    Returns:
        flight_s (longest flight, s), rise_m (highest pelvis rise above the standing level during a
        flight of at least :data:`MIN_FLIGHT_S`; 0 without such a flight), standing_m (the level),
        touches_floor (some joint comes within 0.10 m of y = 0), jump (both thresholds met and
        the motion touches the floor).
    """
    j = _joints(joints)
    found = flights(j)
    level = standing_level(j)
    longest = max((e - s for s, e in found), default=0) / fps
    rise = 0.0
    for s, e in found:
        if (e - s) / fps >= MIN_FLIGHT_S - 1e-9 and np.isfinite(level):
            rise = max(rise, float(j[s:e, 0, 1].max() - level))
    touches = not bool(never_touches(j)[0])
    return {"flight_s": float(longest), "rise_m": rise, "standing_m": level, "touches_floor": touches,
            "jump": bool(touches and longest >= MIN_FLIGHT_S - 1e-9 and rise >= MIN_RISE_M)}


def root_speed(joints: np.ndarray, fps: float = FPS) -> float:
    """Mean horizontal (X–Z) pelvis speed (m/s) over the motion."""
    j = _joints(joints)
    return float(np.linalg.norm(np.diff(j[:, 0, [0, 2]], axis=0), axis=1).mean() * fps)


def wilson(successes: int, n: int, confidence: float = 0.95) -> tuple[float, float, float]:
    """(fraction, low, high): the Wilson score interval of a binomial fraction (NaN for n = 0)."""
    if n <= 0:
        return float("nan"), float("nan"), float("nan")
    if not 0 <= successes <= n:
        raise SimdiffError(f"successes must be in [0, {n}], got {successes}")
    ci = sps.binomtest(int(successes), int(n)).proportion_ci(confidence, method="wilson")
    return successes / n, float(ci.low), float(ci.high)


def quartiles(values: Sequence[float]) -> dict[str, float]:
    """{n, q1, median, q3} of ``values`` (NaN quartiles when empty)."""
    v = np.asarray(list(values), dtype=np.float64)
    if v.size == 0:
        return {"n": 0, "q1": float("nan"), "median": float("nan"), "q3": float("nan")}
    q1, med, q3 = np.percentile(v, [25, 50, 75])
    return {"n": int(v.size), "q1": float(q1), "median": float(med), "q3": float(q3)}
