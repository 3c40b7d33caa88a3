"""A second try under weak gravity: the source slowed to the same Froude number.

Under ``|g_z| < 9.81`` the flight clock (:mod:`simdiff.sim.flight`) keeps the mocap's take-off
speed, so flights last ``2v/|g|``; a run's stride then lands with a pitch its Earth-timed
stance cannot undo, and most low-g rollouts of clips with flight fall.
A motion that is *dynamically similar* to the source
under ``g`` is the source slowed by ``s = sqrt(9.81/|g|)``: every position is the same, every
velocity is divided by ``s`` and every acceleration by ``s²`` (the Froude number v²/(g·L)
stays the source's), so the floor, the legs and the weight stand in Earth's proportions.
People in reduced gravity do move this way: they pick their gait by the Froude number
(walk-run transition near Fr ≈ 0.5 in simulated reduced gravity). Flights of the slowed source
last ``s`` times longer and rise as high as at Earth (ballistic with take-off speed ``v/s``).

:func:`project` tracks the source as given first (higher jumps, the flight clock) and makes
this second try only when that rollout fell or strayed from the source's pose
(:attr:`RetimeConfig.pose_trigger`); it keeps the better of the two (a finished one over a
fall, then the lower pose d_L2). Off by default in :func:`simdiff.sim.project.project`; on for
the augmentation (``simdiff data augment --no-retime`` switches it off). Earth and stronger
gravity, and wind at Earth gravity, are never re-timed.

Only the reference is slowed; the body, its gains and the tracker are as at Earth (giving
the actuators the similar strength, kp × |g|/9.81 and kd × sqrt(|g|/9.81), kept fewer pairs
on a 28-pair sample, 5 against 9).

Measured on train clips with flight of the all-source corpus (augmentation filter), one try → with
the second try: kept at g ∈ [−3, −1) 10 → 32 % (200 clips), [−5, −3) 16 → 57 %, [−8.5, −5) 34 → 47 %
(100 clips; Earth 39 %); CPU per pair 0.7 → 2.3 s at [−3, −1).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from simdiff.errors import SimdiffError
from simdiff.motion.io.resample import frames_at
from simdiff.sim.env import EARTH_GRAVITY


@dataclass(frozen=True)
class RetimeConfig:
    """When and how much :func:`simdiff.sim.project.project` re-times a weak-gravity source.

    Attributes:
        exponent: time scale ``(9.81/|g_z|) ** exponent``; 0.5 is dynamic similarity (Froude).
        pose_trigger: retry a finished rollout whose pose d_L2 (normalised units, against the
            re-timed source) is above this; 6.5 is about the pose bound the augmentation
            filter calibrated on the all-source corpus (6.557). Without a normaliser only falls trigger.
        max_scale: the longest slow-down (3.13 at g = −1 with the default exponent).
    """

    exponent: float = 0.5
    pose_trigger: float = 6.5
    max_scale: float = 4.0

    def __post_init__(self) -> None:
        if not (0.0 < self.exponent <= 1.0):
            raise SimdiffError(f"retime exponent must be in (0, 1], got {self.exponent}")
        if not self.max_scale >= 1.0:
            raise SimdiffError(f"retime max_scale must be >= 1, got {self.max_scale}")

    def scale(self, gravity: float) -> float:
        """Slow-down factor for ``gravity`` (m/s², negative = down): 1 at |g_z| ≥ 9.81."""
        g = abs(float(gravity))
        if g >= abs(EARTH_GRAVITY) or g <= 0.0:
            return 1.0
        return min(self.max_scale, (abs(EARTH_GRAVITY) / g) ** self.exponent)

    def should_retry(self, status: str, pose_d_l2: float) -> bool:
        """True when a first rollout (``status``, its pose d_L2; NaN without normaliser) earns a second try."""
        if status != "ok":
            return True
        return bool(np.isfinite(pose_d_l2) and pose_d_l2 > self.pose_trigger)


def stretch(joints: np.ndarray, scale: float) -> np.ndarray:
    """The motion slowed by ``scale`` (≥ 1): same frame rate, ``round((T − 1)·scale) + 1`` frames.

    Args:
        joints: (T, J, 3) positions (metres) at a fixed frame rate.
        scale: slow-down factor; 1 returns a float32 copy.
    Returns:
        (T', J, 3) float32, frame ``i`` = the source at time ``i / scale`` (linear interpolation).
    """
    j = np.asarray(joints, dtype=np.float64)
    if j.ndim != 3 or j.shape[0] < 2:
        raise SimdiffError(f"expected joints of shape (T>=2, J, 3), got {j.shape}")
    if not (math.isfinite(scale) and scale >= 1.0):
        raise SimdiffError(f"stretch scale must be >= 1, got {scale}")
    T = j.shape[0]
    n = int(round((T - 1) * scale)) + 1
    return frames_at(j, np.minimum(np.arange(n) / scale, T - 1)).astype(np.float32)


def better(first: tuple[str, float], second: tuple[str, float]) -> bool:
    """True when the second try (status, cost) beats the first: finished over fell, then the lower cost (pose d_L2
    for the re-timed try, CLoSD sliding for :mod:`simdiff.sim.fallback`'s); a NaN cost loses, a tie keeps the first."""
    ok1, ok2 = first[0] == "ok", second[0] == "ok"
    if ok1 != ok2:
        return ok2
    p1, p2 = first[1], second[1]
    if not np.isfinite(p2):
        return False
    return (not np.isfinite(p1)) or p2 < p1
