"""Flights that follow gravity: the reference clock waits while the simulation flies (online).

This is the tracker's clock on simulated contacts during a rollout; the offline definition of
flight on a finished motion (corpus report, augment signal, eval response) is
:mod:`simdiff.motion.flight`.

Under φ the simulated flight lasts as long as the take-off speed and g_z make it
(t = 2·v/|g|), not as long as the mocap's. :class:`FlightClock` maps every control step of a
rollout to the reference frame the tracker aims at:

* in stance the reference advances one frame per control step;
* while the simulation flies during a reference flight ``[s, e)`` the reference frame follows
  the *simulated* flight's progress, measured on the COM vertical velocity
  (``f = (v₀ − v_z) / 2v₀``, linear in time for a ballistic body: frame ``s + f·(e − s)``),
  and waits at the last airborne frame ``e − 1`` until the simulation touches down;
* when the simulation touches down (descending) during a reference flight, the reference
  jumps to the landing frame ``e`` and resumes from the landing pose (a short, high-g flight);
* when the simulation is in the air while the reference stands (a push that became a hop
  under low gravity), the clock holds its frame until touchdown.

So a low-g rollout is longer than its input; every wait is bounded (``max_wait_s`` per
flight, ``max_extra_s`` in all). The clock's log (reference frame per control step) gives the
time alignment between rollout and source (:func:`aligned_source`).
"""

from __future__ import annotations

import copy
from dataclasses import dataclass

import numpy as np

from simdiff.errors import SimdiffError
from simdiff.motion.flight import runs
from simdiff.motion.io.resample import frames_at


@dataclass(frozen=True)
class FlightConfig:
    """Options of :class:`FlightClock`.

    Attributes:
        min_frames: reference airborne runs shorter than this (control frames) are not flights.
        lookahead: a simulated take-off up to this many control frames before a reference
            flight starts belongs to that flight (the clock moves to its first frame).
        min_takeoff_vz: below this simulated take-off speed (m/s) the flight progress is
            counted in control steps instead of by the COM velocity.
        hold_after: control steps the simulation must be airborne while the reference stands
            before the clock holds (a foot bounce or a run's short flight never stops the
            clock). 2 made the Earth runs 16_45 and 49_04 fall (the clock held while the runner
            was between steps); 4 tracks both, as without the clock.
        max_wait_s: longest wait per flight (s); then the clock resumes.
        max_extra_s: longest total extension of a rollout (s).
    """

    min_frames: int = 2
    lookahead: int = 4
    min_takeoff_vz: float = 0.2
    hold_after: int = 4
    max_wait_s: float = 6.0
    max_extra_s: float = 20.0


def reference_flights(contact: np.ndarray, min_frames: int = 2) -> list[tuple[int, int]]:
    """Half-open runs ``[s, e)`` of reference frames with no foot contact, stance on both sides.

    Args:
        contact: (K, 4) bool foot-box contacts of the reference.
        min_frames: shortest run counted (control frames).
    """
    contact = np.asarray(contact, dtype=bool)
    if contact.ndim != 2:
        raise SimdiffError(f"contact must be (K, boxes), got shape {contact.shape}")
    air = ~contact.any(axis=1)
    return [(s, e) for s, e in runs(air) if s > 0 and e < len(air) and e - s >= min_frames]


class FlightClock:
    """Reference frame per control step of a rollout (see the module docstring).

    Args:
        contact: (K, 4) reference foot contacts at the control rate.
        control_hz: control rate (1/s).
        config: :class:`FlightConfig`.
    Use: ``r = clock.frame`` for the first step; after each control step call
    ``clock.advance(touching, com_vz)`` with the simulation's state at its end; stop when
    :attr:`done`. :attr:`log` holds the frame of every step so far.
    """

    def __init__(self, contact: np.ndarray, control_hz: float = 30.0, config: FlightConfig = FlightConfig()) -> None:
        self.cfg = config
        self.K = int(np.asarray(contact).shape[0])
        self.flights = reference_flights(contact, config.min_frames)
        self.flight_of = np.full(self.K, -1)
        for i, (s, e) in enumerate(self.flights):
            self.flight_of[s:e] = i
        self.max_wait = int(np.ceil(config.max_wait_s * control_hz))
        self.max_steps = self.K - 1 + int(np.ceil(config.max_extra_s * control_hz))
        self.frame = 0
        self.steps = 0
        self.air_steps = 0  # control steps the simulation has been airborne in a row
        self.v0 = 0.0  # COM v_z at the first airborne step
        self.waited = 0  # control steps held in the current event
        self.current = -1  # the reference flight the simulated flight belongs to
        self.log: list[int] = [0]

    @property
    def done(self) -> bool:
        """The reference has reached its last frame, or the total extension is used up."""
        return self.frame >= self.K - 1 or self.steps >= self.max_steps

    @property
    def extra_steps(self) -> int:
        """Control steps the rollout has taken beyond the reference clock."""
        return self.steps - self.frame

    def snapshot(self) -> "FlightClock":
        """A copy to restore after a rewind."""
        return copy.deepcopy(self)

    def advance(self, touching: bool, com_vz: float) -> int:
        """Move to the next control step given the simulation at the end of this one; returns the frame."""
        r, cfg = self.frame, self.cfg
        nxt = r + 1
        if not touching:
            if self.air_steps == 0:
                self.v0 = float(com_vz)
                self.waited = 0
                self.current = self._flight_ahead(r)
            self.air_steps += 1
            fl = self.current
            if fl >= 0:  # flying through a reference flight: follow the simulated flight's progress
                s, e = self.flights[fl]
                nxt = max(r + 1, s)
                if self.v0 >= cfg.min_takeoff_vz:
                    f = (self.v0 - float(com_vz)) / (2.0 * self.v0)
                    nxt = max(r, s + int(np.floor(f * (e - s))))
                if nxt >= e:  # the reference would land: wait at its last airborne frame
                    nxt = e - 1
            elif self.air_steps >= cfg.hold_after or self._after_flight(r):
                nxt = r  # the reference stands, the simulation still flies: hold the frame
            if nxt == r:
                self.waited += 1
                if self.waited > self.max_wait:
                    nxt = r + 1
        else:
            landed = self.air_steps > 0 and com_vz < 0
            if landed and self.current >= 0:
                nxt = max(r + 1, self.flights[self.current][1])  # touchdown: resume from the landing pose
            if landed or self.air_steps == 0:
                self.current = -1
            self.air_steps = 0
            self.waited = 0
        self.frame = int(min(nxt, self.K - 1))
        self.steps += 1
        self.log.append(self.frame)
        return self.frame

    def _flight_ahead(self, r: int) -> int:
        """The reference flight frame r is in, or that starts within ``lookahead`` frames; else −1."""
        if self.flight_of[r] >= 0:
            return int(self.flight_of[r])
        for i, (s, _) in enumerate(self.flights):
            if r < s <= r + self.cfg.lookahead:
                return i
        return -1

    def _after_flight(self, r: int) -> bool:
        """Frame r is the landing frame of a reference flight (the reference has just landed)."""
        return r > 0 and self.flight_of[r - 1] >= 0 and self.flight_of[r] < 0


def aligned_source(joints: np.ndarray, ref_frames: np.ndarray, control_hz: float, fps: float, n_out: int) -> np.ndarray:
    """The source motion re-timed onto the rollout's clock.

    Args:
        joints: (T, 22, 3) source joints at ``fps``.
        ref_frames: (N+1,) reference (control) frame of each control step of the rollout.
        control_hz: control rate; fps: source and output rate.
        n_out: output frames.
    Returns:
        (n_out, 22, 3) source joints at the reference time each output frame was aimed at
        (linear interpolation), float32.
    """
    joints = np.asarray(joints, dtype=np.float64)
    ref_t = np.asarray(ref_frames, dtype=np.float64) / control_hz  # source time per control step
    t_out = np.arange(n_out) / fps
    step_t = np.arange(len(ref_t)) / control_hz
    src_t = np.interp(t_out, step_t, ref_t)
    return frames_at(joints, np.clip(src_t * fps, 0, joints.shape[0] - 1)).astype(np.float32)


def source_time(ref_frames: np.ndarray, control_hz: float, fps: float, n_out: int) -> np.ndarray:
    """(n_out,) source time (s) each output frame at ``fps`` follows (see :func:`aligned_source`)."""
    ref_t = np.asarray(ref_frames, dtype=np.float64) / control_hz
    step_t = np.arange(len(ref_t)) / control_hz
    return np.interp(np.arange(n_out) / fps, step_t, ref_t)
