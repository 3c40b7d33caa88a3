"""Inverse kinematics: HumanML3D joint positions → humanoid qpos (closed form + Gauss-Newton).

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
so clamping errors do not propagate as offsets. A few damped Gauss-Newton iterations per
frame (:class:`GaussNewtonIK`, :func:`ik_sequence`) polish the result where clamping or
bone lengths differ, optionally with extra tasks (:class:`IKTask`: hold a foot flat).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from simdiff.motion.quaternion import cross3, xyzw_to_wxyz
from simdiff.sim.humanoid import BODY_NAMES, BODY_PARENT, BODY_TO_HML, model_index
from simdiff.sim.retarget.config import RetargetConfig

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
    return np.stack([primary, s, cross3(primary, s)], axis=-1)


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
    qpos[:, 3:7] = xyzw_to_wxyz(Rotation.from_matrix(Rw["Pelvis"]).as_quat())
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
                R = _aim(u, ey, d, cross3(ez, _unit(d)))
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


# IK weight of each HumanML3D joint (feet and pelvis matter most for dynamics).
_IK_WEIGHTS = np.ones(22)
_IK_WEIGHTS[[0]] = 3.0
_IK_WEIGHTS[[7, 8, 10, 11]] = 3.0
_IK_WEIGHTS[[12, 15]] = 0.5


@dataclass
class IKTask:
    """An extra IK task: hold body ``body`` at ``pos`` (world) and, if given, at rotation ``rot``."""

    body: int
    pos: np.ndarray
    rot: np.ndarray | None
    weight: float


class GaussNewtonIK:
    """Damped Gauss-Newton IK of one frame's 22 joint positions (+ extra tasks), hinges clamped."""

    def __init__(self, model, cfg: RetargetConfig) -> None:
        import mujoco

        self.mj = mujoco
        self.m = model
        self.d = mujoco.MjData(model)
        self.ix = model_index(model)
        self.cfg = cfg
        self.nv = model.nv
        self.jacp = np.zeros((3, model.nv))
        self.jacr = np.zeros((3, model.nv))
        self.lo = model.jnt_range[1:, 0]
        self.hi = model.jnt_range[1:, 1]
        self.posture = _posture_weights(model)
        # dof d moves HumanML3D joint i iff the dof's body is the joint's body or an ancestor
        self.mask = np.zeros((22, model.nv))
        for i, b in enumerate(self.ix.hml_bodies):
            chain = set()
            while b > 0:
                chain.add(b)
                b = model.body_parentid[b]
            self.mask[i] = [model.dof_bodyid[v] in chain for v in range(model.nv)]
        self.hinge_jnt = np.arange(1, model.njnt)
        self.w = np.repeat(_IK_WEIGHTS, 3)

    def _joint_jacobian(self) -> np.ndarray:
        """(66, nv) position Jacobian of the 22 HumanML3D joints at the current kinematics.

        Hinge column: axis × (p − anchor); free-joint columns: identity (translation) and the
        body-frame rotation axes × (p − root); zero where the dof is not an ancestor.
        """
        d = self.d
        p = d.xpos[self.ix.hml_bodies]  # (22, 3)
        axes = np.empty((self.nv, 3))
        anchors = np.empty((self.nv, 3))
        root = self.ix.pelvis
        axes[3:6] = d.xmat[root].reshape(3, 3).T
        anchors[3:6] = d.xpos[root]
        axes[6:] = d.xaxis[self.hinge_jnt]
        anchors[6:] = d.xanchor[self.hinge_jnt]
        J = cross3(axes[None, 3:], p[:, None, :] - anchors[None, 3:])  # (22, nv-3, 3)
        out = np.zeros((22, 3, self.nv))
        out[:, :, 3:] = np.swapaxes(J, 1, 2) * self.mask[:, None, 3:]
        out[:, [0, 1, 2], [0, 1, 2]] = 1.0
        return out.reshape(66, self.nv)

    def solve(self, q: np.ndarray, target: np.ndarray, iters: int, tasks: list[IKTask] = ()) -> tuple[np.ndarray, float]:
        """Gauss-Newton on the 22 joint positions ``target`` (22, 3) world + extra tasks.

        Returns the solution and its mean joint error (m).
        """
        mj, m, d = self.mj, self.m, self.d
        nv = self.nv
        lam = self.cfg.ik_damping
        pw = self.cfg.posture_weight * self.posture
        q = q.copy()
        diag = np.arange(nv)
        for _ in range(iters):
            d.qpos[:] = q
            mj.mj_kinematics(m, d)
            J = self._joint_jacobian()
            if tasks:
                mj.mj_comPos(m, d)  # cdof for mj_jacBody
            e = (target - d.xpos[self.ix.hml_bodies]).ravel()
            H = J.T @ (J * self.w[:, None])
            g = J.T @ (self.w * e)
            for task in tasks:
                mj.mj_jacBody(m, d, self.jacp, self.jacr, task.body)
                H += task.weight * (self.jacp.T @ self.jacp)
                g += task.weight * (self.jacp.T @ (task.pos - d.xpos[task.body]))
                if task.rot is not None:
                    cur = d.xmat[task.body].reshape(3, 3)
                    H += 0.3 * task.weight * (self.jacr.T @ self.jacr)
                    E = task.rot @ cur.T  # small-angle rotation error: vee(E - Eᵀ) / 2
                    rv = 0.5 * np.array([E[2, 1] - E[1, 2], E[0, 2] - E[2, 0], E[1, 0] - E[0, 1]])
                    g += 0.3 * task.weight * (self.jacr.T @ rv)
            H[diag, diag] += lam
            H[diag[6:], diag[6:]] += pw
            g[6:] -= pw * q[7:]
            dq = np.linalg.solve(H, g)
            mj.mj_integratePos(m, q, dq, 1.0)
            q[7:] = np.clip(q[7:], self.lo, self.hi)
            if np.max(np.abs(dq)) < 1e-5:
                break
        d.qpos[:] = q
        mj.mj_kinematics(m, d)
        err = float(np.linalg.norm(target - d.xpos[self.ix.hml_bodies], axis=1).mean())
        return q, err


def _posture_weights(model) -> np.ndarray:
    """(69,) relative posture-prior weight per hinge: secondary axes (knee and elbow
    side-bend and twist) are discouraged so that IK bends them like hinges."""
    import mujoco

    w = np.ones(model.njnt - 1)
    for i in range(1, model.njnt):
        name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, i)
        if name.endswith(("Knee_x", "Knee_z", "Elbow_x")):
            w[i - 1] = 50.0
        elif name.endswith(("Elbow_z", "Ankle_z", "Ankle_x", "Toe_x", "Toe_z", "Hand_x", "Hand_y", "Hand_z")):
            w[i - 1] = 5.0
    return w


def ik_sequence(model, target: np.ndarray, cfg: RetargetConfig, tasks: list[list[IKTask]] | None = None,
                init: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Per-frame IK: closed-form, then Gauss-Newton polishing.

    Args:
        target: (T, 22, 3) world joint positions.
        tasks: optional per-frame extra tasks.
        init: optional (T, nq) starting solution; default the closed-form IK of ``target``
            (:func:`analytic_ik`).
    Returns:
        qpos (T, nq) and the mean joint error per frame (T,) in metres.
    """
    ik = GaussNewtonIK(model, cfg)
    if init is None:
        init, iters = analytic_ik(model, target), cfg.ik_polish_iters
    else:
        iters = cfg.ik_iters
    T = target.shape[0]
    qs = np.zeros((T, model.nq))
    errs = np.zeros(T)
    for t in range(T):
        qs[t], errs[t] = ik.solve(init[t], target[t], iters, tasks[t] if tasks is not None else [])
    return qs, errs
