"""Procedural motions on the canonical skeleton, for tests, demos and benchmarks.

Not data: a simple sinusoidal gait with an optional turn, built by forward kinematics so
bone lengths are exact. Metres, Y-up, 20 fps; frame 0 faces +Z.
"""

from __future__ import annotations

import numpy as np

from simdiff.motion.kinematics import forward_kinematics
from simdiff.motion.skeleton import CANONICAL_OFFSETS, FPS, NUM_JOINTS


def _axis_angle(axis: np.ndarray, angle: np.ndarray) -> np.ndarray:
    axis = np.asarray(axis, dtype=np.float64) / np.linalg.norm(axis)
    half = np.asarray(angle, dtype=np.float64)[..., None] / 2
    return np.concatenate([np.cos(half), np.sin(half) * axis], axis=-1)


def walk(
    frames: int = 80,
    *,
    speed: float = 1.2,
    turn_rate: float = 0.0,
    stride_hz: float = 1.0,
    amplitude: float = 0.5,
    bounce: float = 0.03,
    phase: float = 0.0,
) -> np.ndarray:
    """A walking-like motion.

    Args:
        frames: number of frames T (20 fps).
        speed: forward root speed in m/s.
        turn_rate: yaw rate in rad/s (positive turns left, towards +X).
        stride_hz: gait cycles per second.
        amplitude: hip swing amplitude in radians.
        bounce: vertical pelvis oscillation in metres.
        phase: gait phase offset in radians.
    Returns:
        (T, 22, 3) float32 joints; the lowest joint over the clip is at y = 0.
    """
    t = np.arange(frames) / FPS
    w = 2 * np.pi * stride_hz * t + phase
    quats = np.zeros((frames, NUM_JOINTS, 4))
    quats[..., 0] = 1.0
    yaw = turn_rate * t
    quats[:, 0] = _axis_angle([0, 1, 0], yaw)
    x_axis = np.array([1.0, 0.0, 0.0])
    swing = amplitude * np.sin(w)
    # A joint's quaternion orients the bone from its parent to it: thighs are joints 4/5,
    # shins 7/8, upper arms 18/19, forearms 20/21.
    quats[:, 4] = _axis_angle(x_axis, -swing)  # left thigh
    quats[:, 5] = _axis_angle(x_axis, swing)  # right thigh
    quats[:, 7] = _axis_angle(x_axis, 0.6 * np.clip(np.sin(w + np.pi / 2), 0, None) + 0.05)
    quats[:, 8] = _axis_angle(x_axis, 0.6 * np.clip(np.sin(w - np.pi / 2), 0, None) + 0.05)
    quats[:, 18] = _axis_angle(x_axis, 0.6 * swing)  # left upper arm, opposite to the left leg
    quats[:, 19] = _axis_angle(x_axis, -0.6 * swing)
    quats[:, 20] = _axis_angle(x_axis, np.full(frames, -0.3))  # elbows slightly bent
    quats[:, 21] = _axis_angle(x_axis, np.full(frames, -0.3))
    # Feet point forward (their rest offset is +Z already); arms hang down.

    heading = np.stack([np.sin(yaw), np.zeros_like(yaw), np.cos(yaw)], axis=-1)
    if turn_rate == 0.0:
        root_xz = np.cumsum(np.concatenate([[0.0], np.full(frames - 1, speed / FPS)]))[:, None] * heading
    else:
        step = heading * speed / FPS
        root_xz = np.concatenate([np.zeros((1, 3)), np.cumsum(step[:-1], axis=0)], axis=0)
    root = root_xz + np.array([0.0, 0.92, 0.0]) + np.stack(
        [np.zeros(frames), bounce * np.cos(2 * w), np.zeros(frames)], axis=-1
    )
    joints = forward_kinematics(quats, root, CANONICAL_OFFSETS)
    joints[..., 1] -= joints[..., 1].min()
    return joints.astype(np.float32)


def jump(frames: int = 60, *, height: float = 0.4, start: int = 20, airtime: float = 0.5) -> np.ndarray:
    """A standing vertical jump: crouch, a ballistic flight of ``airtime`` s, land.

    Returns:
        (T, 22, 3) float32 joints, standing on y = 0 outside the flight.
    """
    base = walk(frames, speed=0.0, amplitude=0.0, bounce=0.0)
    t = (np.arange(frames) - start) / FPS
    lift = np.where((t > 0) & (t < airtime), 4 * height * (t / airtime) * (1 - t / airtime), 0.0)
    out = base.astype(np.float64)
    out[..., 1] += lift[:, None]
    return out.astype(np.float32)
