"""Euler-angle rotation matrices (numpy, column vectors, right-handed)."""

from __future__ import annotations

import numpy as np

_AXES = {"X": 0, "Y": 1, "Z": 2}


def axis_matrix(axis: str, angle: np.ndarray) -> np.ndarray:
    """Rotations by ``angle`` radians (...,) about one of "X", "Y", "Z": (..., 3, 3)."""
    angle = np.asarray(angle, dtype=np.float64)
    c, s = np.cos(angle), np.sin(angle)
    one, zero = np.ones_like(angle), np.zeros_like(angle)
    a = axis.upper()
    if a == "X":
        rows = ((one, zero, zero), (zero, c, -s), (zero, s, c))
    elif a == "Y":
        rows = ((c, zero, s), (zero, one, zero), (-s, zero, c))
    elif a == "Z":
        rows = ((c, -s, zero), (s, c, zero), (zero, zero, one))
    else:
        raise ValueError(f"unknown rotation axis {axis!r}")
    return np.stack([np.stack(r, axis=-1) for r in rows], axis=-2)


def euler_to_matrix(angles: np.ndarray, order: str, *, degrees: bool = True) -> np.ndarray:
    """Matrix ``R[order[0]](a0) @ R[order[1]](a1) @ ...`` (the first axis is outermost).

    This is the BVH channel convention: for ``Zrotation Xrotation Yrotation`` the matrix is
    Rz @ Rx @ Ry, i.e. Y is applied to a vector first. For "first listed is applied first"
    (ASF/AMC), pass the axes and angles reversed.

    Args:
        angles: (..., K) angles, one per letter of ``order``.
        order: K axis letters, e.g. "ZXY".
        degrees: whether ``angles`` are degrees (else radians).
    Returns:
        (..., 3, 3) rotation matrices (float64); identity when K == 0.
    """
    angles = np.asarray(angles, dtype=np.float64)
    if angles.shape[-1] != len(order):
        raise ValueError(f"{angles.shape[-1]} angles for order {order!r}")
    if degrees:
        angles = np.deg2rad(angles)
    out = np.broadcast_to(np.eye(3), angles.shape[:-1] + (3, 3)).copy()
    for k, axis in enumerate(order):
        out = out @ axis_matrix(axis, angles[..., k])
    return out


def matrix_to_euler(matrix: np.ndarray, order: str, *, degrees: bool = True) -> np.ndarray:
    """Inverse of :func:`euler_to_matrix` for a 3-letter order with distinct axes.

    Args:
        matrix: (..., 3, 3) rotation matrices.
        order: e.g. "ZXY" (outermost first).
    Returns:
        (..., 3) angles; the middle angle lies in [-90, 90] degrees.
    """
    m = np.asarray(matrix, dtype=np.float64)
    if len(order) != 3 or len(set(order.upper())) != 3 or not set(order.upper()) <= set(_AXES):
        raise ValueError(f"order must be three distinct axes, got {order!r}")
    # closed form, not scipy's Rotation: importing scipy.spatial costs 0.4 s of a cold `generate --format bvh`
    i, j, k = (_AXES[a] for a in order.upper())
    sign = 1.0 if (j - i) % 3 == 1 else -1.0  # +1 for cyclic orders (XYZ, YZX, ZXY)
    cos_middle = np.hypot(m[..., i, i], m[..., i, j])
    middle = np.arctan2(sign * m[..., i, k], cos_middle)  # atan2, not asin: full precision next to ±90°
    locked = cos_middle < 1e-9  # middle angle ±90°: the first and last axes coincide
    first = np.where(locked, np.arctan2(sign * m[..., k, j], m[..., j, j]),
                     np.arctan2(-sign * m[..., j, k], m[..., k, k]))
    last = np.where(locked, 0.0, np.arctan2(-sign * m[..., i, j], m[..., i, i]))
    angles = np.stack([first, middle, last], axis=-1)
    return np.rad2deg(angles) if degrees else angles
