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
