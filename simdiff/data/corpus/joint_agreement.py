"""Agreement of two copies of one capture (e.g. CMU AMC and BVH: same capture, two rigs, two retargets).

Both copies are retargeted to the 22 HumanML3D joints at 120 fps (the AMC capture rate, so
the two can be put in sync to 1/120 s), run through the corpus pipeline's joint stage
(canonical skeleton, floor, facing +Z: :func:`simdiff.motion.features.process_joints`),
then aligned: the time lag (within ±0.2 s) and the rigid motion (rotation about Y plus a
3D translation) that minimise the mean per-joint distance. The residual distances, in
metres, measure how much the two retargets disagree.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from simdiff.motion.skeleton import JOINT_NAMES

CHECK_FPS: float = 120.0
"""Frame rate of the comparison (frames per second)."""
MAX_LAG_S: float = 0.2
"""Largest time offset searched (seconds)."""


@dataclass
class Agreement:
    """Result of one AMC/BVH comparison (distances in metres, lag in seconds).

    ``root_relative`` is the pose-only error: per-frame centroids removed after alignment.
    """

    trial: str
    frames: int
    lag_s: float
    yaw_deg: float
    mpjpe: float
    root_relative: float
    floor_offset: float
    per_joint: np.ndarray  # (22,) mean distance of each joint after alignment
    body_offset: np.ndarray | None = None  # (22, 3) mean b - a in a's body frame (left, up, forward)

    def to_dict(self) -> dict[str, object]:
        """JSON-friendly form (metres, seconds, degrees)."""
        return {
            "trial": self.trial, "frames": self.frames, "lag_s": self.lag_s, "yaw_deg": self.yaw_deg,
            "mpjpe": self.mpjpe, "root_relative": self.root_relative, "floor_offset": self.floor_offset,
            "per_joint": [float(x) for x in self.per_joint],
            "body_offset": None if self.body_offset is None else np.round(self.body_offset, 5).tolist(),
        }

    @classmethod
    def from_dict(cls, d: dict[str, object]) -> Agreement:
        """Inverse of :meth:`to_dict`."""
        values = dict(d)
        values["per_joint"] = np.asarray(values["per_joint"], dtype=np.float64)
        if values.get("body_offset") is not None:
            values["body_offset"] = np.asarray(values["body_offset"], dtype=np.float64)
        return cls(**values)  # type: ignore[arg-type]

    @property
    def worst_joint(self) -> str:
        """Name of the joint with the largest mean distance."""
        return JOINT_NAMES[int(np.argmax(self.per_joint))]


def rigid_yaw_align(target: np.ndarray, moving: np.ndarray) -> tuple[np.ndarray, float]:
    """Rotate ``moving`` about Y and translate it (3D) onto ``target``, least squares.

    Args:
        target, moving: (T, J, 3) positions.
    Returns:
        (aligned (T, J, 3), yaw in radians).
    """
    a = target.reshape(-1, 3)
    b = moving.reshape(-1, 3)
    ca, cb = a.mean(axis=0), b.mean(axis=0)
    a0, b0 = a - ca, b - cb
    num = float(np.sum(a0[:, 0] * b0[:, 2] - a0[:, 2] * b0[:, 0]))
    den = float(np.sum(a0[:, 0] * b0[:, 0] + a0[:, 2] * b0[:, 2]))
    yaw = float(np.arctan2(num, den))
    c, s = np.cos(yaw), np.sin(yaw)
    rot = np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])
    return ((b - cb) @ rot.T + ca).reshape(moving.shape), yaw


def compare_joints(a: np.ndarray, b: np.ndarray, fps: float, trial: str = "") -> Agreement:
    """Agreement of two (T, 22, 3) versions of one motion at ``fps`` (see module docstring)."""
    best: tuple[float, int, np.ndarray, np.ndarray, float] | None = None
    max_lag = int(round(MAX_LAG_S * fps))
    for lag in range(-max_lag, max_lag + 1):
        ia, ib = max(0, lag), max(0, -lag)
        n = min(len(a) - ia, len(b) - ib)
        if n < max(2, int(0.5 * min(len(a), len(b)))):
            continue
        aa = a[ia : ia + n]
        bb, yaw = rigid_yaw_align(aa, b[ib : ib + n])
        err = float(np.linalg.norm(aa - bb, axis=-1).mean())
        if best is None or err < best[0]:
            best = (err, lag, aa, bb, yaw)
    if best is None:
        raise ValueError("motions too short to compare")
    err, lag, aa, bb, yaw = best
    ia, ib = max(0, lag), max(0, -lag)
    n = len(aa)
    centred = (aa - aa.mean(axis=1, keepdims=True)) - (bb - bb.mean(axis=1, keepdims=True))
    pose_only = np.linalg.norm(centred, axis=-1).mean()
    floor = float(np.mean(a[ia : ia + n, 0, 1]) - np.mean(b[ib : ib + n, 0, 1]))
    return Agreement(
        trial=trial, frames=n, lag_s=lag / fps, yaw_deg=float(np.degrees(yaw)), mpjpe=err,
        root_relative=float(pose_only), floor_offset=floor,
        per_joint=np.linalg.norm(aa - bb, axis=-1).mean(axis=0), body_offset=body_frame_offset(aa, bb),
    )


def body_frame_offset(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Mean of ``b - a`` per joint in the body frame of ``a`` (x left, y up, z forward).

    Args:
        a, b: (T, 22, 3) aligned positions in metres.
    Returns:
        (22, 3) metres; a constant offset means the two joint maps place a joint differently.
    """
    from simdiff.motion.skeleton import FACE_JOINTS

    r_hip, l_hip, r_sh, l_sh = FACE_JOINTS
    left = (a[:, l_hip] - a[:, r_hip]) + (a[:, l_sh] - a[:, r_sh])
    left[:, 1] = 0.0
    left /= np.maximum(np.linalg.norm(left, axis=-1, keepdims=True), 1e-9)
    up = np.broadcast_to(np.array([0.0, 1.0, 0.0]), left.shape)
    forward = np.cross(left, up)
    frame = np.stack([left, up, forward], axis=1)  # (T, 3, 3) rows: body axes in world
    return np.einsum("tij,tkj->tki", frame, b - a).mean(axis=0)
