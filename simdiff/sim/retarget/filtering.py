"""Despiking, Gaussian smoothing, cubic resampling and finite-difference velocities."""

from __future__ import annotations

import numpy as np
from scipy.interpolate import CubicSpline
from scipy.ndimage import gaussian_filter1d


def despike(joints: np.ndarray, distance: float) -> np.ndarray:
    """Replace isolated outlier samples (mocap glitches) by their neighbours' mean.

    A joint sample farther than ``distance`` (m) from the median of its ±2-frame
    neighbourhood (itself excluded) while those neighbours agree with each other is an
    outlier; it becomes the mean of the adjacent samples. The first and last frames have
    neighbours on one side only: they are compared with the linear extrapolation of the
    next two frames (which must themselves lie on a line with the third) and replaced by it,
    so that a fast motion's first frame is not mistaken for a glitch and is not frozen.
    """
    T = joints.shape[0]
    if distance <= 0 or T < 5:
        return joints
    out = joints.copy()
    pad = np.concatenate([joints[2:0:-1], joints, joints[-2:-4:-1]], 0)  # mirror 2 frames
    nb = np.stack([pad[i : i + T] for i in (0, 1, 3, 4)], 0)  # (4, T, 22, 3)
    med = np.median(nb, axis=0)
    far = np.linalg.norm(joints - med, axis=-1) > distance
    spread = np.linalg.norm(nb - med, axis=-1).max(0) < distance
    bad = far & spread
    for t, a, b, c in ((0, 1, 2, 3), (T - 1, T - 2, T - 3, T - 4)):
        pred = 2 * joints[a] - joints[b]
        line = np.linalg.norm(joints[a] - (2 * joints[b] - joints[c]), axis=-1) < distance
        bad[t] = (np.linalg.norm(joints[t] - pred, axis=-1) > distance) & line
        out[t, bad[t]] = pred[bad[t]]
    for t, j in zip(*np.nonzero(bad[1:-1])):
        t += 1
        out[t, j] = 0.5 * (joints[t - 1, j] + joints[t + 1, j])
    return out


def smooth(x: np.ndarray, sigma: float) -> np.ndarray:
    """Gaussian filter along axis 0 with odd-reflection padding (keeps boundary velocity)."""
    if sigma <= 0 or x.shape[0] < 3:
        return x
    pad = min(int(np.ceil(4 * sigma)), x.shape[0] - 1)
    head = 2 * x[:1] - x[1 : pad + 1][::-1]
    tail = 2 * x[-1:] - x[-pad - 1 : -1][::-1]
    y = gaussian_filter1d(np.concatenate([head, x, tail], 0), sigma, axis=0, mode="nearest")
    return y[pad : pad + x.shape[0]]


def continuous_quats(q: np.ndarray) -> np.ndarray:
    q = q.copy()
    for t in range(1, q.shape[0]):
        if np.dot(q[t], q[t - 1]) < 0:
            q[t] = -q[t]
    return q


def resample_qpos(qpos: np.ndarray, fps_in: float, fps_out: float) -> np.ndarray:
    """Cubic resampling of a qpos trajectory (root quaternion renormalised)."""
    T = qpos.shape[0]
    t_in = np.arange(T) / fps_in
    n_out = int(np.ceil((T - 1) / fps_in * fps_out - 1e-9)) + 1  # covers the last input frame
    t_out = np.arange(n_out) / fps_out
    x = qpos.copy()
    x[:, 3:7] = continuous_quats(x[:, 3:7])
    if T < 2:
        return x
    if T >= 3:
        y = CubicSpline(t_in, x, axis=0, bc_type="natural", extrapolate=True)(t_out)
    else:  # two frames: linear, extrapolated
        y = x[0] + (x[1] - x[0]) * (t_out / t_in[1])[:, None]
    y[:, 3:7] /= np.linalg.norm(y[:, 3:7], axis=1, keepdims=True)
    return y


def finite_velocity(model, qpos: np.ndarray, dt: float) -> np.ndarray:
    """(K, nv) central-difference velocities of a qpos trajectory."""
    import mujoco

    K = qpos.shape[0]
    v = np.zeros((K, model.nv))
    if K < 2:
        return v
    tmp = np.zeros(model.nv)
    for t in range(K):
        a, b = max(t - 1, 0), min(t + 1, K - 1)
        mujoco.mj_differentiatePos(model, tmp, (b - a) * dt, qpos[a], qpos[b])
        v[t] = tmp
    return v
