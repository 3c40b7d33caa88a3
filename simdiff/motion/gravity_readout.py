"""Gravity read back from a motion's flights: a body in free flight moves its centre of mass on a parabola whose
curvature is g.

For every flight of :func:`simdiff.motion.flight.flights`, the frames where every foot joint is more than
:data:`simdiff.motion.flight.LIFT` (5 cm) above its own ground level are kept (take-off and landing pushes left
out); with at least :data:`MIN_FIT_FRAMES` of them, the height of the tracked point is fitted with
``y(t) = g/2 t² + v t + c`` by least squares. The point is the centre of mass of a segment model (de Leva's mass
fractions on the 22 joints, :func:`centre_of_mass`) or the pelvis. A motion's reading is the frame-weighted mean of
its flights' g. Joints (T, 22, 3) metres, Y up, HumanML3D order; g in m/s² (negative: down).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from simdiff.errors import SimdiffError
from simdiff.motion.flight import check_joints, feet_up, flights, runs
from simdiff.motion.skeleton import FPS

MIN_FIT_FRAMES: int = 5
"""Airborne frames a flight needs (0.25 s at 20 fps) for its parabola to be read."""

SEGMENTS: tuple[tuple[int, int, float], ...] = (
    (0, 9, 0.4346),  # trunk: pelvis to upper spine
    (12, 15, 0.0694),  # head and neck
    (16, 18, 0.0271), (17, 19, 0.0271),  # upper arms
    (18, 20, 0.0162), (19, 21, 0.0162),  # forearms
    (20, 20, 0.0061), (21, 21, 0.0061),  # hands, at the wrists
    (1, 4, 0.1416), (2, 5, 0.1416),  # thighs
    (4, 7, 0.0433), (5, 8, 0.0433),  # shanks
    (7, 10, 0.0137), (8, 11, 0.0137),  # feet
)
"""(joint, joint, mass fraction): each segment's mass at the midpoint of two joints (de Leva 1996, male adult)."""


@dataclass(frozen=True)
class FlightFit:
    """One flight's parabola.

    Attributes:
        start, end: the fitted frames ``[start, end)``.
        gravity: fitted g in m/s² (negative: down).
        rmse_m: root-mean-square residual of the fit in metres.
        apex_m: the fitted peak height minus the height at ``start``, metres.
    """

    start: int
    end: int
    gravity: float
    rmse_m: float
    apex_m: float


def centre_of_mass(joints: np.ndarray) -> np.ndarray:
    """(T, 3) centre of mass of the segment model :data:`SEGMENTS`."""
    j = check_joints(joints)
    mass = np.array([m for _, _, m in SEGMENTS])
    mids = np.stack([(j[:, a] + j[:, b]) / 2.0 for a, b, _ in SEGMENTS], axis=1)  # (T, S, 3)
    return np.einsum("tsk,s->tk", mids, mass / mass.sum())


def fit_parabola(height: np.ndarray, fps: float = FPS) -> tuple[float, float, float]:
    """Least-squares ``y = g/2 t² + v t + c`` of (N,) heights sampled at ``fps``: (g, rmse in m, apex gain in m)."""
    t = np.arange(len(height)) / fps
    coef, *_ = np.linalg.lstsq(np.stack([t**2 / 2.0, t, np.ones_like(t)], axis=1), height, rcond=None)
    g, v, c = (float(x) for x in coef)
    fitted = g * t**2 / 2.0 + v * t + c
    peak_t = float(np.clip(-v / g, t[0], t[-1])) if g < 0 else float(t[np.argmax(fitted)])
    apex = g * peak_t**2 / 2.0 + v * peak_t
    return g, float(np.sqrt(np.mean((height - fitted) ** 2))), float(apex)


def flight_fits(joints: np.ndarray, fps: float = FPS, point: str = "com") -> list[FlightFit]:
    """The parabola of every readable flight (see the module docstring); ``point``: ``com`` or ``pelvis``."""
    j = check_joints(joints)
    if point not in ("com", "pelvis"):
        raise SimdiffError(f"point must be 'com' or 'pelvis', got {point!r}")
    height = centre_of_mass(j)[:, 1] if point == "com" else j[:, 0, 1]
    up = feet_up(j).all(axis=1)
    out = []
    for s, e in flights(j):
        for a, b in runs(up[s:e]):
            if b - a >= MIN_FIT_FRAMES:
                g, rmse, apex = fit_parabola(height[s + a:s + b], fps)
                out.append(FlightFit(s + a, s + b, g, rmse, apex))
    return out


def read_gravity(joints: np.ndarray, fps: float = FPS, point: str = "com") -> dict[str, float] | None:
    """The motion's gravity reading: frame-weighted mean g of its flights, their worst fit RMSE (m), the airborne
    frames used and the number of flights; None when no flight is readable."""
    fits = flight_fits(joints, fps, point)
    if not fits:
        return None
    frames = np.array([f.end - f.start for f in fits], dtype=np.float64)
    return {"gravity": float(np.average([f.gravity for f in fits], weights=frames)),
            "rmse_m": float(max(f.rmse_m for f in fits)), "frames": float(frames.sum()), "flights": float(len(fits))}
