"""Quaternion and rotation helpers on numpy arrays (w, x, y, z; float64 inside).

All functions broadcast over leading dimensions: a quaternion array has shape (..., 4), a
vector array (..., 3), a rotation matrix (..., 3, 3), a continuous-6D rotation (..., 6).
"""

from __future__ import annotations

import math

import numpy as np


def wxyz_to_xyzw(q: np.ndarray) -> np.ndarray:
    """Scalar-first (w, x, y, z: ours, MuJoCo's) → scalar-last (x, y, z, w: scipy's ``Rotation``), (..., 4)."""
    return np.asarray(q)[..., [1, 2, 3, 0]]


def xyzw_to_wxyz(q: np.ndarray) -> np.ndarray:
    """Scalar-last (x, y, z, w: scipy's ``Rotation``) → scalar-first (w, x, y, z), (..., 4)."""
    return np.asarray(q)[..., [3, 0, 1, 2]]


def cross3(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Cross product of 3-vectors along the last axis, broadcasting (..., 3).

    The same products and differences as ``np.cross`` (bit-identical results) without its
    per-call overhead (axis moves and checks: about 0.1 ms, paid hundreds of times per tracked motion).
    """
    a, b = np.asarray(a), np.asarray(b)
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    return np.stack([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0], axis=-1)


def qnormalize(q: np.ndarray) -> np.ndarray:
    """Unit quaternions, (..., 4)."""
    return q / np.linalg.norm(q, axis=-1, keepdims=True)


def qinv(q: np.ndarray) -> np.ndarray:
    """Conjugate (the inverse of a unit quaternion), (..., 4)."""
    return q * np.array([1.0, -1.0, -1.0, -1.0])


def qmul(q: np.ndarray, r: np.ndarray) -> np.ndarray:
    """Hamilton product ``q * r`` (apply r, then q), (..., 4)."""
    w1, x1, y1, z1 = np.moveaxis(q, -1, 0)
    w2, x2, y2, z2 = np.moveaxis(r, -1, 0)
    return np.stack(
        [
            w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2,
            w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
            w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
            w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2,
        ],
        axis=-1,
    )


def qrot(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Rotate vectors v (..., 3) by unit quaternions q (..., 4)."""
    u = q[..., 1:]
    w = q[..., :1]
    uv = np.cross(u, v)
    uuv = np.cross(u, uv)
    return v + 2.0 * (w * uv + uuv)


def qbetween(v0: np.ndarray, v1: np.ndarray) -> np.ndarray:
    """Shortest-arc unit quaternion rotating direction v0 onto v1, (..., 4).

    Undefined for exactly opposite vectors (as in HumanML3D).
    """
    axis = np.cross(v0, v1)
    w = np.sqrt((v0**2).sum(-1) * (v1**2).sum(-1)) + (v0 * v1).sum(-1)
    return qnormalize(np.concatenate([w[..., None], axis], axis=-1))


def quat_to_matrix(q: np.ndarray) -> np.ndarray:
    """Rotation matrices (..., 3, 3) of unit quaternions (..., 4)."""
    w, x, y, z = np.moveaxis(q, -1, 0)
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
            np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
            np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
        ],
        axis=-2,
    )


def matrix_to_cont6d(m: np.ndarray) -> np.ndarray:
    """Continuous 6D rotation: the first two matrix columns concatenated, (..., 6)."""
    return np.concatenate([m[..., :, 0], m[..., :, 1]], axis=-1)


def quat_to_cont6d(q: np.ndarray) -> np.ndarray:
    """Continuous 6D rotation of unit quaternions, (..., 6)."""
    return matrix_to_cont6d(quat_to_matrix(q))


def cont6d_to_matrix(d6: np.ndarray) -> np.ndarray:
    """Rotation matrices (..., 3, 3) from continuous 6D (Gram-Schmidt on the two columns)."""
    a = d6[..., 0:3]
    b = d6[..., 3:6]
    x = a / np.linalg.norm(a, axis=-1, keepdims=True)
    z = np.cross(x, b)
    z = z / np.linalg.norm(z, axis=-1, keepdims=True)
    y = np.cross(z, x)
    return np.stack([x, y, z], axis=-1)


def yaw_quat(angle: np.ndarray) -> np.ndarray:
    """Quaternion (cos a, 0, sin a, 0) for a half-angle array a, (..., 4): a rotation of 2a about +Y."""
    angle = np.asarray(angle, dtype=np.float64)
    zeros = np.zeros_like(angle)
    return np.stack([np.cos(angle), zeros, np.sin(angle), zeros], axis=-1)


def quat_error(q_ref: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Rotation vector (3,) taking unit quaternion q to q_ref, both (4,) wxyz (radians).

    Scalar code on purpose: called at every physics step of the simulator.
    """
    w1, x1, y1, z1 = q_ref
    w2, x2, y2, z2 = q[0], -q[1], -q[2], -q[3]
    e = np.array([
        w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2,
        w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
        w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
        w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2,
    ])
    if e[0] < 0:
        e = -e
    v = e[1:]
    s = math.sqrt(v.dot(v))  # np.linalg.norm(v), without its per-call overhead
    if s < 1e-12:
        return np.zeros(3)
    return e[1:] / s * 2.0 * np.arctan2(s, e[0])
