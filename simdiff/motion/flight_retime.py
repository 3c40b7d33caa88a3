"""A motion's flights re-timed to another gravity: the take-off is kept, the flight becomes ballistic under g.

Under weaker gravity a jumper pushes off as on Earth (the legs' strength does not change), so the centre of mass
leaves the ground with the same velocity and flies longer and higher: the flight lasts until the parabola
``y = y₀ + v t + g t²/2`` returns to the landing height, while the horizontal velocity stays the take-off's. This is
what the simulator's flight clock (:mod:`simdiff.sim.flight`) does during a rollout, made on the motion alone, so
it also works where a rollout falls.

For every flight with at least :data:`simdiff.motion.gravity_readout.MIN_FIT_FRAMES` frames on which every foot is
up (the frames :func:`simdiff.motion.gravity_readout.flight_fits` reads), the centre of mass's take-off position
and velocity are fitted by a parabola over those frames; the new flight's centre of mass follows the parabola
under ``gravity`` plus a term linear in time that meets the motion's own centre of mass at both ends (so it is
continuous and its curvature is exactly ``gravity``); the pose around the centre of mass is the source's, played
at the flight's phase. Frames after a flight move by the extra horizontal travel. Stance frames are unchanged.
Joints (T, 22, 3) metres, Y up, 20 fps.
"""

from __future__ import annotations

import numpy as np

from simdiff.errors import SimdiffError
from simdiff.motion.flight import check_joints
from simdiff.motion.gravity_readout import centre_of_mass, flight_fits
from simdiff.motion.io.resample import frames_at
from simdiff.motion.skeleton import FPS

MAX_FLIGHT_S: float = 6.0
"""Longest re-timed flight (s): a take-off at 2.5 m/s under g −1 flies 5 s."""


def retime_flights(joints: np.ndarray, gravity: float, fps: float = FPS) -> np.ndarray:
    """(T', 22, 3) float32: ``joints`` with each readable flight re-timed to a ballistic flight under ``gravity``.

    Args:
        joints: (T, 22, 3) metres, Y up.
        gravity: g_z in m/s², negative (down).
        fps: frame rate of ``joints`` and of the result.
    Raises:
        SimdiffError: gravity not negative and finite; a take-off that would fly longer than :data:`MAX_FLIGHT_S`.
    """
    j = check_joints(joints).astype(np.float64)
    if not (np.isfinite(gravity) and gravity < 0.0):
        raise SimdiffError(f"gravity must be a negative number of m/s², got {gravity}")
    com = centre_of_mass(j)
    pieces: list[np.ndarray] = []
    shift = np.zeros(3)  # extra horizontal travel of the flights so far
    done = 0
    for fit in flight_fits(j, fps, point="com"):
        a, b = fit.start, fit.end
        pieces.append(j[done:a] + shift)
        t0 = np.arange(b - a) / fps
        vy = float(np.polyfit(t0, com[a:b, 1], 2)[1])  # take-off vertical speed, m/s
        h_speed = np.array([np.polyfit(t0, com[a:b, k], 1)[0] for k in (0, 2)])  # horizontal speed, m/s
        rise = com[b - 1, 1] - com[a, 1]  # landing height above the take-off's
        disc = vy * vy + 2.0 * gravity * rise
        # the later root of vy D + g D²/2 = rise; a landing out of reach (stronger g) is met at the apex
        duration = (-vy - np.sqrt(disc)) / gravity if disc > 0.0 else -vy / gravity
        if not 0.0 < duration <= MAX_FLIGHT_S:
            raise SimdiffError(f"the flight at frames {a}-{b} would last {duration:.1f} s under g {gravity} "
                               f"(0 to {MAX_FLIGHT_S} s allowed)")
        t = np.arange(max(int(round(duration * fps)), 1) + 1) / fps  # the frame clock keeps the curvature exact
        u = t / t[-1]
        offsets = frames_at(j[a:b] - com[a:b, None, :], u * (b - a - 1))  # the pose around the COM, by phase
        path = np.repeat(com[a][None], len(t), axis=0)
        path[:, 1] += vy * t + gravity * t * t / 2.0
        path[:, [0, 2]] += t[:, None] * h_speed
        # a term linear in time meets the landing height (curvature unchanged)
        path[:, 1] += u * (com[b - 1, 1] - path[-1, 1])
        pieces.append(path[:, None, :] + offsets + shift)
        extra = path[-1] - com[b - 1]
        shift = shift + np.array([extra[0], 0.0, extra[2]])
        done = b
    pieces.append(j[done:] + shift)
    return np.concatenate(pieces).astype(np.float32)
