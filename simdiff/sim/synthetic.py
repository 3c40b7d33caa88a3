"""Synthetic reference motions made with the humanoid's own kinematics (for tests, benchmarks).

All return HumanML3D joints (T, 22, 3) float32, Y-up metres, 20 fps, facing +Z.
"""

from __future__ import annotations

import numpy as np

from simdiff.sim.retarget.kinematics import qpos_to_joints
from simdiff.sim.humanoid import load_model


def _joint_cols(model, names: list[str]) -> list[int]:
    import mujoco

    return [model.jnt_qposadr[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, n)] for n in names]


def _crouch(model, qpos: np.ndarray, amount: np.ndarray) -> None:
    """Bend hips/knees/ankles by ``amount`` (T,) in [0, 1] keeping the feet flat; lowers the root."""
    hip = _joint_cols(model, ["L_Hip_y", "R_Hip_y"])
    knee = _joint_cols(model, ["L_Knee_y", "R_Knee_y"])
    ankle = _joint_cols(model, ["L_Ankle_y", "R_Ankle_y"])
    a = 0.9 * amount[:, None]  # knee angle / 2
    qpos[:, hip] = -a
    qpos[:, knee] = 2 * a
    qpos[:, ankle] = -a
    shin, thigh = 0.43, 0.39
    qpos[:, 2] -= (shin + thigh) * (1 - np.cos(a[:, 0]))


def standing(frames: int = 40) -> np.ndarray:
    """The upright rest pose held still."""
    m = load_model()
    q = np.tile(m.qpos0, (frames, 1))
    return qpos_to_joints(m, q)


def squat(frames: int = 60, depth: float = 0.5, cycles: float = 1.0) -> np.ndarray:
    """Slow knee-bend cycles (depth in [0, 1] of the crouch)."""
    m = load_model()
    q = np.tile(m.qpos0, (frames, 1))
    t = np.arange(frames) / (frames - 1)
    _crouch(m, q, depth * 0.5 * (1 - np.cos(2 * np.pi * cycles * t)))
    return qpos_to_joints(m, q)


def vertical_jump(height: float = 0.15, g: float = 9.81, pre: int = 16, post: int = 20) -> np.ndarray:
    """Crouch, ballistic flight of ``height`` metres under gravity g, land, stand up (20 fps)."""
    m = load_model()
    fps = 20.0
    t_air = 2 * np.sqrt(2 * height / g)
    n_air = int(np.ceil(t_air * fps))
    T = pre + n_air + post
    q = np.tile(m.qpos0, (T, 1))
    amount = np.zeros(T)
    amount[:pre] = 0.35 * np.sin(np.linspace(0, np.pi, pre)) ** 2  # crouch and extend
    land = np.arange(post)
    amount[pre + n_air :] = 0.3 * np.sin(np.linspace(0, np.pi, post)) ** 2 * (land < post)
    _crouch(m, q, amount)
    tt = (np.arange(n_air) + 0.5) / fps
    tt = tt * (t_air / (n_air / fps))
    q[pre : pre + n_air, 2] += np.sqrt(2 * g * height) * tt - 0.5 * g * tt**2
    ank = _joint_cols(m, ["L_Ankle_y", "R_Ankle_y"])
    q[pre : pre + n_air, ank] = 0.4  # toes pointed in flight
    return qpos_to_joints(m, q)


def walk_in_place(frames: int = 60, step_hz: float = 1.0, lift: float = 0.35) -> np.ndarray:
    """Alternating knee lifts (marching on the spot)."""
    m = load_model()
    q = np.tile(m.qpos0, (frames, 1))
    t = np.arange(frames) / 20.0
    ph = 2 * np.pi * step_hz * t
    for side, s in (("L", 1.0), ("R", -1.0)):
        up = lift * np.clip(s * np.sin(ph), 0, None)
        hip, knee = _joint_cols(m, [f"{side}_Hip_y", f"{side}_Knee_y"])
        q[:, hip] = -up * 2
        q[:, knee] = up * 4
    return qpos_to_joints(m, q)
