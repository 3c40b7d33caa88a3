"""Ground clean-up of retargeted joints whose source has no ground contact (DeepMimic)."""

from __future__ import annotations

import numpy as np

from simdiff.motion.skeleton import FPS

GROUND_PERCENTILE: float = 5.0
"""Percentile of the per-frame lowest joint taken as the ground in :func:`lift_penetrations`."""
MAX_LIFT: float = 0.06
"""Largest vertical correction (m) of :func:`lift_penetrations`; deeper dips are left alone."""


def lift_penetrations(joints: np.ndarray, fps: float = FPS) -> np.ndarray:
    """Raise the frames that sink below the ground, then put the trial on the floor.

    The DeepMimic retargets were made without ground contact: in 1-5 % of the frames a toe
    (push-off with a rigid box foot) or a limb (rolls, get-ups) dips 2-10 cm below the level
    the body otherwise stands or lies on. The corpus floor is the lowest joint of a clip, so
    those few frames lifted the floor under all the others (median floating 79 mm vs 21 mm
    for AMC). Here the ground is the :data:`GROUND_PERCENTILE` th percentile of the per-frame
    lowest joint; a frame below it is raised by the missing height (at most
    :data:`MAX_LIFT`), the correction smoothed over 0.25 s so that no jerk is added.

    Args:
        joints: (T, 22, 3) metres, Y-up.
    Returns:
        (T, 22, 3) float32, floor (lowest joint) at y = 0.
    """
    from scipy.ndimage import maximum_filter1d, uniform_filter1d

    out = np.array(joints, dtype=np.float64, copy=True)
    lowest = out[..., 1].min(axis=-1)
    if lowest.size < 3:
        return out.astype(np.float32)
    ground = float(np.percentile(lowest, GROUND_PERCENTILE))
    lift = np.clip(ground - lowest, 0.0, MAX_LIFT)
    size = max(1, int(round(0.25 * fps)))
    lift = uniform_filter1d(maximum_filter1d(lift, size, mode="nearest"), size, mode="nearest")
    out[..., 1] += lift[:, None]
    out[..., 1] -= out[..., 1].min()
    return out.astype(np.float32)


MIN_SLOPE: float = 0.004
"""Smallest ground slope (rise per metre, ~0.23 deg) that :func:`level_ground` removes."""
MAX_SLOPE: float = 0.05
"""Largest slope (~2.9 deg) taken as a capture-floor tilt; steeper fits are real terrain."""
MIN_TRAVEL: float = 1.0
"""Metres of horizontal spread of the contacts needed to estimate a slope."""
MAX_SPREAD: float = 0.015
"""Metres: median distance of the contacts from the fitted plane for a trusted fit."""


def ground_slope(joints: np.ndarray) -> tuple[np.ndarray, float, float, float]:
    """Tilt of the ground along the clip's main travel direction.

    The per-frame lowest joint is projected on the principal horizontal axis ``u`` of its
    path (left/right feet are too close together to fit a sideways tilt) and a line
    ``y = slope * s + c`` is fitted to its lower envelope (refitted twice, dropping frames
    more than 3 cm above the line).

    Args:
        joints: (T, 22, 3) metres, Y-up.
    Returns:
        (u (2,) unit xz direction, slope (rise per metre), median absolute residual of the
        kept contacts (m), travel: extent of the contacts along u (m)).
    """
    arr = np.asarray(joints, dtype=np.float64)
    low = arr[np.arange(arr.shape[0]), arr[..., 1].argmin(axis=-1)]  # (T, 3)
    xz = low[:, [0, 2]] - low[:, [0, 2]].mean(axis=0)
    _, _, vt = np.linalg.svd(xz, full_matrices=False)
    u = vt[0]
    along = xz @ u
    keep = np.ones(len(low), dtype=bool)
    coef = np.zeros(2)
    resid = np.zeros(len(low))
    for _ in range(3):
        design = np.column_stack([along[keep], np.ones(int(keep.sum()))])
        coef, *_ = np.linalg.lstsq(design, low[keep, 1], rcond=None)
        resid = low[:, 1] - (coef[0] * along + coef[1])
        keep = resid < 0.03
        if keep.sum() < 10:
            break
    spread = float(np.median(np.abs(resid[keep]))) if keep.any() else float("inf")
    return u, float(coef[0]), spread, float(np.ptp(along))


def level_ground(joints: np.ndarray, fps: float = FPS) -> np.ndarray:
    """Remove a small tilt of the capture floor, then put the clip on the floor.

    Some conversions (the CMU Motionbuilder walks of subject 08) stand on a floor that rises
    5-7 cm over a 4 m walk, so the clip floor (lowest joint) leaves the end of the walk
    floating. A line is fitted to the per-frame lowest joint along the travel direction
    (:func:`ground_slope`); when the contacts spread at least :data:`MIN_TRAVEL` m along it,
    lie within :data:`MAX_SPREAD` of the line and its slope is between :data:`MIN_SLOPE`
    and :data:`MAX_SLOPE`, heights are sheared by it (``y -= slope * (xz . u)``). Otherwise
    the joints are only put on the floor.

    Args:
        joints: (T, 22, 3) metres, Y-up.
        fps: frame rate (unused; kept for the rig ``finish`` signature).
    Returns:
        (T, 22, 3) float32, floor (lowest joint) at y = 0.
    """
    out = np.array(joints, dtype=np.float64, copy=True)
    if out.shape[0] >= 10:
        u, slope, spread, travel = ground_slope(out)
        if travel >= MIN_TRAVEL and spread <= MAX_SPREAD and MIN_SLOPE <= abs(slope) <= MAX_SLOPE:
            out[..., 1] -= slope * (out[..., 0] * u[0] + out[..., 2] * u[1])
    out[..., 1] -= out[..., 1].min()
    return out.astype(np.float32)
