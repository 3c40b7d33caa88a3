"""Forward kinematics of humanoid states: HumanML3D joints, foot-box soles, COM height.

Shapes: qpos (T, nq); joints (T, 22, 3) metres (world Z-up or HumanML3D Y-up as named).
"""

from __future__ import annotations

import numpy as np

from simdiff.sim.humanoid import ModelIndex, model_index, world_to_hml


def qpos_to_world(model, qpos: np.ndarray, index: ModelIndex | None = None) -> np.ndarray:
    """World positions (T, 22, 3) of the HumanML3D joints for qpos (T, nq)."""
    import mujoco

    ix = index or model_index(model)
    data = mujoco.MjData(model)
    out = np.empty((qpos.shape[0], 22, 3))
    for t in range(qpos.shape[0]):
        data.qpos[:] = qpos[t]
        mujoco.mj_kinematics(model, data)
        out[t] = data.xpos[ix.hml_bodies]
    return out


def qpos_to_joints(model, qpos: np.ndarray, index: ModelIndex | None = None) -> np.ndarray:
    """HumanML3D joints (T, 22, 3) float32, Y-up metres, of humanoid states qpos (T, nq)."""
    return world_to_hml(qpos_to_world(model, qpos, index)).astype(np.float32)


def joints_to_features(joints: np.ndarray) -> np.ndarray:
    """(T, 22, 3) joints → (T-1, 263) HumanML3D features (lazy import of the motion package)."""
    from simdiff.motion.features import joints_to_features as j2f

    return j2f(np.asarray(joints, dtype=np.float64))


def box_bottom_corners(model, data, geom: int) -> np.ndarray:
    """(4, 3) world positions of the 4 lowest corners of box geom ``geom``."""
    size = model.geom_size[geom]
    signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], dtype=float)
    local = signs * size
    world = data.geom_xpos[geom] + local @ data.geom_xmat[geom].reshape(3, 3).T
    return world[np.argsort(world[:, 2])[:4]]


def foot_geoms(model) -> list[int]:
    """Box geoms of (L foot, L toe, R foot, R toe)."""
    import mujoco

    out = []
    for name in ("L_Ankle", "L_Toe", "R_Ankle", "R_Toe"):
        b = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, name)
        out.append(int(np.flatnonzero(model.geom_bodyid == b)[0]))
    return out


def foot_heights(model, qpos: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Lowest sole height (T, 4) and centre xy (T, 4, 2) of the 4 foot boxes (LF, LT, RF, RT)."""
    import mujoco

    d = mujoco.MjData(model)
    geoms = foot_geoms(model)
    h = np.zeros((qpos.shape[0], 4))
    xy = np.zeros((qpos.shape[0], 4, 2))
    for t in range(qpos.shape[0]):
        d.qpos[:] = qpos[t]
        mujoco.mj_kinematics(model, d)
        for k, g in enumerate(geoms):
            c = box_bottom_corners(model, d, g)
            h[t, k] = c[:, 2].min()
            xy[t, k] = d.geom_xpos[g, :2]
    return h, xy


def com_height(model, qpos: np.ndarray) -> np.ndarray:
    """(T,) whole-body COM height (m) of each pose."""
    import mujoco

    d = mujoco.MjData(model)
    pelvis = model_index(model).pelvis
    out = np.zeros(qpos.shape[0])
    for t in range(qpos.shape[0]):
        d.qpos[:] = qpos[t]
        mujoco.mj_kinematics(model, d)
        mujoco.mj_comPos(model, d)
        out[t] = d.subtree_com[pelvis, 2]
    return out
