"""The offline definition of flight: when a motion's feet are all off the ground.

This is the one airborne rule of the project, used by the corpus report
(:mod:`simdiff.data.corpus.report`), the augmentation signal table
(:func:`simdiff.data.augment.signal.measure`) and the environment-response evaluation
(:mod:`simdiff.eval.response`). The tracker's online flight clock
(:mod:`simdiff.sim.flight`) is a different thing: it reads simulated contacts while a rollout runs.

Input: joints (T, 22, 3), HumanML3D order, metres, Y-up, ``fps`` frames per second (20).
The ground is estimated per foot joint, not taken from y = 0, so that the rule works both on
corpus clips (floor at 0) and on generated or simulated motions whose floor may be offset:

* each foot joint (:data:`FEET`: both ankles and both toes) has its own low level, the
  :data:`GROUND_PERCENTILE` th percentile of its height over the motion (robust to a glitch
  frame; it needs the foot on the ground in at least that share of the frames);
* a frame is in the air when every foot joint is more than :data:`LIFT` above its low level;
* a flight is a run of such frames, extended on both sides to the frames where every foot joint
  is still more than :data:`LIFT_EDGE` up (take-off and landing are then where the feet really
  leave and reach the ground), at least :data:`MIN_FRAMES` frames long, not starting at frame 0
  (a motion that starts in the air has no take-off to measure from).

Heights only, no velocity: a jump's apex is slow but airborne. Other joints are not checked:
a handstand is not flight (the feet stay at their own, high, level) but the legs of a roll or a
cartwheel can read as a short flight; the corpus report names the longest flights to check.
"""

from __future__ import annotations

import numpy as np

from simdiff.errors import SimdiffError
from simdiff.motion.skeleton import FPS

FEET: tuple[int, ...] = (7, 10, 8, 11)
"""HumanML3D left ankle, left foot (toe), right ankle, right foot (toe)."""
GROUND_PERCENTILE: float = 5.0
"""Percentile of a foot joint's height over the motion taken as its ground level."""
LIFT: float = 0.05
"""m: a foot joint this far above its own ground level is off the floor."""
LIFT_EDGE: float = 0.01
"""m: a flight found with :data:`LIFT` extends to the frames where every foot joint is this far up."""
MIN_FRAMES: int = 2
"""Shortest flight, in frames (0.1 s at 20 fps)."""
MIN_FLIGHT_S: float = 0.2
"""s: a clip whose longest flight lasts this long or longer has real flight (corpus report, augment report)."""


def check_joints(joints: np.ndarray) -> np.ndarray:
    """``joints`` as float64 (T, 22, 3), T ≥ 2; a one-line :class:`SimdiffError` otherwise."""
    j = np.asarray(joints, dtype=np.float64)
    if j.ndim != 3 or j.shape[1:] != (22, 3) or j.shape[0] < 2:
        raise SimdiffError(f"expected joints of shape (T>=2, 22, 3), got {j.shape}")
    return j


def runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """Half-open ``[start, end)`` runs of True in a (T,) bool mask."""
    m = np.concatenate([[False], np.asarray(mask, dtype=bool), [False]])
    edges = np.flatnonzero(m[1:] != m[:-1])
    return [(int(s), int(e)) for s, e in zip(edges[::2], edges[1::2])]


def heights_over_ground(joints: np.ndarray) -> np.ndarray:
    """(T, 4) m: each foot joint of :data:`FEET` over its own ground level (see the module docstring)."""
    h = check_joints(joints)[:, FEET, 1]
    return h - np.percentile(h, GROUND_PERCENTILE, axis=0)


def feet_up(joints: np.ndarray, lift: float = LIFT) -> np.ndarray:
    """(T, 4) bool: each foot joint of :data:`FEET` more than ``lift`` m above its own ground level."""
    return heights_over_ground(joints) > lift


def flights(joints: np.ndarray) -> list[tuple[int, int]]:
    """Flight phases ``[start, end)`` in frames, in time order (see module docstring)."""
    air = feet_up(joints).all(axis=1)
    edge = feet_up(joints, LIFT_EDGE).all(axis=1)
    T = air.shape[0]
    out: list[tuple[int, int]] = []
    for s, e in runs(air):
        while s > 1 and edge[s - 1]:
            s -= 1
        while e < T and edge[e]:
            e += 1
        if e - s >= MIN_FRAMES and s > 0 and (not out or s >= out[-1][1]):
            out.append((s, e))
    return out


def has_flight(longest_flight_s: float) -> bool:
    """True when a clip's longest flight (``flight_stats(...)["flight_s"]``, s) is real flight (≥ :data:`MIN_FLIGHT_S`)."""
    return float(longest_flight_s) >= MIN_FLIGHT_S - 1e-9


def airborne(joints: np.ndarray) -> np.ndarray:
    """(T,) bool: the frames inside a flight of :func:`flights`."""
    mask = np.zeros(check_joints(joints).shape[0], dtype=bool)
    for s, e in flights(joints):
        mask[s:e] = True
    return mask


def flight_stats(joints: np.ndarray, fps: float = FPS) -> dict[str, float]:
    """Flights of one motion.

    Returns:
        flights (count), flight_s (longest flight, s), flight_total_s (all flights, s),
        apex_gain_m (root height gain during the longest flight over the frame before take-off;
        0 without flight).
    Raises:
        SimdiffError: not (T, 22, 3) with T ≥ 2.
    """
    j = check_joints(joints)
    found = flights(j)
    out = {"flights": float(len(found)), "flight_s": 0.0,
           "flight_total_s": float(sum(e - s for s, e in found) / fps), "apex_gain_m": 0.0}
    if found:
        s, e = max(found, key=lambda r: r[1] - r[0])
        out["flight_s"] = (e - s) / fps
        out["apex_gain_m"] = float(j[s:e, 0, 1].max() - j[s - 1, 0, 1])
    return out
