"""Faithfulness to the source that does not punish what φ changes (timing, height, speed).

:func:`pose_d_l2` is paper eq. 13 restricted to the *pose* channels of the 263-d HumanML3D
features and taken against the source re-timed onto the rollout's clock
(:func:`simdiff.sim.flight.aligned_source`):

* kept: joint positions relative to the root in the heading frame, horizontal components
  (``ric`` x, z: 42 dims) and the local joint rotations (``rot6d``: 126 dims);
* dropped: root height and the joints' heights (``root_y``, ``ric`` y: a higher or lower
  flight), every velocity channel (``root_rot_vel``, ``root_lin_vel``, ``vel``: a slower fall,
  a longer flight, and the re-timed source stands still while the clock waits) and the foot
  contacts (a flight that lasts longer has more airborne frames).

So it measures whether the rollout still performs the text's motion, pose by pose, not
whether it moves with Earth's timing. Units: normalised feature units, like d_L2.
"""

from __future__ import annotations

import numpy as np

from simdiff.motion.features import SLICES


def pose_feature_mask() -> np.ndarray:
    """(263,) bool: the pose channels compared by :func:`pose_d_l2`."""
    mask = np.zeros(263, dtype=bool)
    ric = np.arange(SLICES["ric"].start, SLICES["ric"].stop)
    mask[ric[(ric - SLICES["ric"].start) % 3 != 1]] = True  # x and z of each joint
    mask[SLICES["rot6d"]] = True
    return mask


def normalized_features(a: np.ndarray, b: np.ndarray, normalizer) -> tuple[np.ndarray, np.ndarray] | None:
    """Normalised (n, 263) features of two joint sequences cut to their common length n.

    Args:
        a, b: (T, 22, 3) and (T', 22, 3) joints (metres, Y-up, 20 fps).
        normalizer: a :class:`simdiff.motion.normalize.Normalizer`.
    Returns:
        (features of a, features of b), or None without a normaliser or with fewer than 2 common frames.
    """
    if normalizer is None:
        return None
    n = min(len(a), len(b))
    if n < 2:
        return None
    from simdiff.sim.retarget import joints_to_features

    return (np.asarray(normalizer.normalize(joints_to_features(a[:n]))),
            np.asarray(normalizer.normalize(joints_to_features(b[:n]))))


def feature_distance(pair: tuple[np.ndarray, np.ndarray] | None, mask: np.ndarray | None = None) -> float:
    """Mean per-frame L2 distance of :func:`normalized_features` (over the channels in ``mask``; NaN for None)."""
    if pair is None:
        return float("nan")
    fr, fo = pair
    if mask is not None:
        fr, fo = fr[:, mask], fo[:, mask]
    return float(np.linalg.norm(fr - fo, axis=-1).mean())


def pose_d_l2(source_aligned: np.ndarray, out_joints: np.ndarray, normalizer) -> float:
    """Mean per-frame L2 distance of the normalised pose channels (see module docstring).

    Args:
        source_aligned: (T, 22, 3) source joints re-timed onto the rollout (metres, Y-up).
        out_joints: (T', 22, 3) rollout joints; both are cut to the common length.
        normalizer: a :class:`simdiff.motion.normalize.Normalizer`; None gives NaN.
    Returns:
        The distance, NaN with fewer than 2 common frames or without a normaliser.
    """
    return feature_distance(normalized_features(source_aligned, out_joints, normalizer), pose_feature_mask())
