"""Analytic (closed-form) inverse kinematics: HumanML3D joint positions → humanoid qpos.

The generated humanoid's body origins *are* the HumanML3D joints and every body frame is
world-aligned at rest, so each body's rotation follows from where its children must go:

* bodies with several children (pelvis: hips + torso; chest: neck + collars) get the
  least-squares rotation of their rest offsets onto the target offsets (Kabsch);
* bodies with one child get the rotation that points the bone exactly at the child, with
  the twist about the bone chosen from a secondary direction: the knee / elbow bending
  plane for thigh and upper arm (blended toward the foot direction / the parent's twist
  when the limb is straight), the parent's hinge axis for shank and forearm, a horizontal
  lateral axis for the foot, and a pelvis-to-chest blend for the spine;
* bodies without a tracked child (toes, head, hands) keep the parent's orientation.

The local rotation is decomposed into the three hinge angles (intrinsic XYZ), choosing the
Euler branch that fits the joint range best, and clamped to the range. The solve runs top
down and is vectorised over frames; each body aims from its *achieved* (clamped) parent,
so clamping errors do not propagate as offsets. A few Gauss-Newton iterations
(:mod:`simdiff.sim.convert`) polish the result where clamping or bone lengths differ.
"""

from __future__ import annotations

import functools

import numpy as np
from scipy.spatial.transform import Rotation

from simdiff.sim.humanoid import BODY_NAMES, BODY_PARENT, BODY_TO_HML

# child body whose joint position fixes a single-child body's bone direction
_AIM_CHILD: dict[str, str] = {
    "L_Hip": "L_Knee", "L_Knee": "L_Ankle", "L_Ankle": "L_Toe",
    "R_Hip": "R_Knee", "R_Knee": "R_Ankle", "R_Ankle": "R_Toe",
    "Torso": "Spine", "Spine": "Chest", "Neck": "Head",
    "L_Thorax": "L_Shoulder", "L_Shoulder": "L_Elbow", "L_Elbow": "L_Wrist",
    "R_Thorax": "R_Shoulder", "R_Shoulder": "R_Elbow", "R_Elbow": "R_Wrist",
}
_KABSCH: dict[str, tuple[str, ...]] = {
    "Pelvis": ("L_Hip", "R_Hip", "Torso"),
    "Chest": ("Neck", "L_Thorax", "R_Thorax"),
}


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.maximum(np.linalg.norm(v, axis=-1, keepdims=True), 1e-12)


def _perp(v: np.ndarray, axis: np.ndarray) -> np.ndarray:
    """Component of v (T, 3) perpendicular to unit ``axis`` (T, 3)."""
    return v - np.sum(v * axis, axis=-1, keepdims=True) * axis


def _frame(primary: np.ndarray, secondary: np.ndarray) -> np.ndarray:
    """(T, 3, 3) orthonormal columns (p, s⊥, p × s⊥) from unit primary and any secondary."""
    s = _unit(_perp(secondary, primary))
    return np.stack([primary, s, np.cross(primary, s)], axis=-1)


def _aim(u_local: np.ndarray, a_local: np.ndarray, d_world: np.ndarray, h_world: np.ndarray) -> np.ndarray:
    """World rotations (T, 3, 3) taking local unit u to world direction d exactly and the
    local secondary axis a toward the world hint h (about d)."""
    T = d_world.shape[0]
    E = _frame(np.broadcast_to(u_local, (T, 3)), np.broadcast_to(a_local, (T, 3)))
    F = _frame(_unit(d_world), h_world)
    return F @ np.swapaxes(E, -1, -2)


def _kabsch(local: np.ndarray, world: np.ndarray) -> np.ndarray:
    """Rotations (T, 3, 3) best mapping local vectors (n, 3) onto world vectors (T, n, 3)."""
    H = np.einsum("ni,tnj->tij", local, world)
    U, _, Vt = np.linalg.svd(H)
    D = np.ones((H.shape[0], 3))
    D[:, 2] = np.sign(np.linalg.det(np.swapaxes(Vt, -1, -2) @ np.swapaxes(U, -1, -2)))
    return np.swapaxes(Vt, -1, -2) @ (D[:, :, None] * np.swapaxes(U, -1, -2))


def _euler_in_range(R_local: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Hinge angles (T, 3) of local rotations: the intrinsic-XYZ branch closest to [lo, hi], clamped."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # gimbal lock: any split of x/z is a valid answer
        a = Rotation.from_matrix(R_local).as_euler("XYZ")
    b = a.copy()
    b[:, 0] += np.pi
    b[:, 1] = np.where(a[:, 1] >= 0, np.pi - a[:, 1], -np.pi - a[:, 1])
    b[:, 2] += np.pi
    b = (b + np.pi) % (2 * np.pi) - np.pi

    def violation(x: np.ndarray) -> np.ndarray:
        return (np.maximum(lo - x, 0) + np.maximum(x - hi, 0)).sum(-1)

    pick = violation(b) < violation(a) - 1e-9
    out = np.where(pick[:, None], b, a)
    return np.clip(out, lo, hi)


@functools.lru_cache(maxsize=4)
def _layout(model) -> dict:
    """Rest offsets, hinge ranges and qpos columns per body (cached per model)."""
    import mujoco

    bid = {n: mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, n) for n in BODY_NAMES}
    out = {"offset": {n: model.body_pos[bid[n]].copy() for n in BODY_NAMES}, "range": {}, "cols": {}}
    for n in BODY_NAMES[1:]:
        jids = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, f"{n}_{a}") for a in "xyz"]
        out["range"][n] = (model.jnt_range[jids, 0].copy(), model.jnt_range[jids, 1].copy())
        out["cols"][n] = np.array([model.jnt_qposadr[j] for j in jids])
    return out


def analytic_ik(model, target: np.ndarray) -> np.ndarray:
    """Closed-form IK of world joint positions.

    Args:
        model: the generated humanoid.
        target: (T, 22, 3) HumanML3D joint positions in MuJoCo world coordinates (Z-up).
    Returns:
        qpos (T, nq).
    """
    lay = _layout(model)
    off = lay["offset"]
    T = target.shape[0]
    P = {n: target[:, BODY_TO_HML[n]] for n in BODY_TO_HML}
    qpos = np.tile(model.qpos0, (T, 1))
    Rw: dict[str, np.ndarray] = {}
    pos: dict[str, np.ndarray] = {"Pelvis": P["Pelvis"]}
    ex, ey, ez = np.eye(3)

    # pelvis (free joint) and the twist hints of the spine
    kids = _KABSCH["Pelvis"]
    Rw["Pelvis"] = _kabsch(np.stack([off[c] for c in kids]), np.stack([P[c] - P["Pelvis"] for c in kids], 1))
    qpos[:, :3] = P["Pelvis"]
    qpos[:, 3:7] = Rotation.from_matrix(Rw["Pelvis"]).as_quat()[:, [3, 0, 1, 2]]
    y_pelvis = Rw["Pelvis"][:, :, 1]
    y_chest = _unit(P["L_Thorax"] - P["R_Thorax"])

    for body in BODY_NAMES[1:]:
        parent = BODY_PARENT[body]
        Rp = Rw[parent]
        pos[body] = pos[parent] + Rp @ off[body]
        here = pos[body]
        if body in _KABSCH:
            kids = _KABSCH[body]
            R = _kabsch(np.stack([off[c] for c in kids]), np.stack([P[c] - here for c in kids], 1))
        elif body in _AIM_CHILD:
            child = _AIM_CHILD[body]
            u = _unit(off[child])
            d = P[child] - here
            side = body[:2]
            if body.endswith("_Hip"):  # twist from the knee bend plane (shank swings to -x)
                shank = P[side + "Ankle"] - P[side + "Knee"]
                bend = -_perp(shank, _unit(d))
                foot = _perp(P[side + "Toe"] - P[side + "Ankle"], _unit(d))
                w = np.clip(np.linalg.norm(bend, axis=-1, keepdims=True) / (0.25 * np.linalg.norm(shank, axis=-1, keepdims=True)), 0, 1)
                R = _aim(u, ex, d, w * _unit(bend) + (1 - w) * _unit(foot))
            elif body.endswith("_Shoulder"):  # twist from the elbow bend plane (forearm swings to +x)
                fore = P[side + "Wrist"] - P[side + "Elbow"]
                bend = _perp(fore, _unit(d))
                w = np.clip(np.linalg.norm(bend, axis=-1, keepdims=True) / (0.25 * np.linalg.norm(fore, axis=-1, keepdims=True)), 0, 1)
                R = _aim(u, ex, d, w * _unit(bend) + (1 - w) * Rp[:, :, 0])
            elif body.endswith(("_Knee", "_Elbow")):  # hinge-like: keep the parent's y axis
                R = _aim(u, ey, d, Rp[:, :, 1])
            elif body.endswith("_Ankle"):  # foot: lateral axis horizontal
                R = _aim(u, ey, d, np.cross(ez, _unit(d)))
            elif body == "Torso":
                R = _aim(u, ey, d, 2 * y_pelvis + y_chest)
            elif body == "Spine":
                R = _aim(u, ey, d, y_pelvis + 2 * y_chest)
            elif body.endswith("_Thorax"):  # collar bone points sideways: keep the parent's x axis
                R = _aim(u, ex, d, Rp[:, :, 0])
            else:  # neck: least twist relative to the parent
                R = _aim(u, ey, d, Rp[:, :, 1])
        else:  # toes, head, hands: no tracked child
            R = Rp
        lo, hi = lay["range"][body]
        ang = _euler_in_range(np.swapaxes(Rp, -1, -2) @ R, lo, hi)
        qpos[:, lay["cols"][body]] = ang
        Rw[body] = Rp @ Rotation.from_euler("XYZ", ang).as_matrix()
    return qpos
