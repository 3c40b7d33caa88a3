"""Inverse-dynamics screen: root residual wrench and joint feed-forward torques of a reference."""

from __future__ import annotations

import numpy as np
from scipy.optimize import nnls

from simdiff.sim.retarget.kinematics import box_bottom_corners, foot_geoms


def inverse_dynamics_screen(model, qpos: np.ndarray, qvel: np.ndarray, qacc: np.ndarray, contact: np.ndarray,
                            friction: float = 0.8, spread: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Root residual wrench and joint feed-forward torques of a reference.

    At each frame the generalised force of the motion without contacts (``mj_inverse`` with
    constraints disabled) is split into what non-negative floor forces in a 4-edge friction
    pyramid at the corners of the touching foot boxes can supply (NNLS on the 6 root rows)
    and the rest, the root residual.

    Args:
        qpos, qvel, qacc: (K, nq/nv) reference.
        contact: (K, 4) touching foot boxes (L foot, L toe, R foot, R toe).
        spread: weight of a ridge term ``spread·||f||²`` (f in N) added to the NNLS, which
            spreads the load over every touching corner instead of the sparse split plain
            NNLS returns (one foot carrying the body while the other carries nothing).
    Returns:
        root_residual (K, 6): force (N, world) and torque (N·m, pelvis frame) rows;
        tau_ff (K, 69): hinge torques (N·m) after subtracting the contact forces.
    """
    import mujoco

    m = model
    saved = m.opt.disableflags
    m.opt.disableflags = saved | int(mujoco.mjtDisableBit.mjDSBL_CONSTRAINT)
    d = mujoco.MjData(m)
    geoms = foot_geoms(m)
    K = qpos.shape[0]
    res = np.zeros((K, 6))
    tau = np.zeros((K, m.nv - 6))
    edges = np.array([[friction, 0, 1], [-friction, 0, 1], [0, friction, 1], [0, -friction, 1]], dtype=float)
    jacp = np.zeros((3, m.nv))
    try:
        for t in range(K):
            d.qpos[:] = qpos[t]
            d.qvel[:] = qvel[t]
            d.qacc[:] = qacc[t]
            mujoco.mj_inverse(m, d)
            b = d.qfrc_inverse.copy()
            cols = []
            for k, g in enumerate(geoms):
                if not contact[t, k]:
                    continue
                for c in box_bottom_corners(m, d, g):
                    mujoco.mj_jac(m, d, jacp, None, c, m.geom_bodyid[g])
                    cols.append(jacp.T @ edges.T)  # (nv, 4)
            if cols:
                A = np.concatenate(cols, 1)
                scale = np.array([1, 1, 1, 3, 3, 3], dtype=float)  # weigh torques (per 0.33 m)
                M, rhs = A[:6] * scale[:, None], b[:6] * scale
                if spread > 0:
                    M = np.vstack([M, np.sqrt(spread) * np.eye(A.shape[1])])
                    rhs = np.concatenate([rhs, np.zeros(A.shape[1])])
                f, _ = nnls(M, rhs, maxiter=200)
                gen = A @ f
            else:
                gen = np.zeros(m.nv)
            res[t] = b[:6] - gen[:6]
            tau[t] = b[6:] - gen[6:]
    finally:
        m.opt.disableflags = saved
    return res, tau
