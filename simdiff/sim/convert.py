"""HumanML3D joints ⇄ humanoid states, and the reference a tracker follows.

Forward (:func:`make_reference`), as the probes found necessary:

1. closed-form IK (:mod:`simdiff.sim.ik`) of the 22 joint positions, polished by a few
   damped Gauss-Newton iterations per frame (joint ranges clamped, a small posture prior);
2. ground alignment and a contact schedule per foot (heel box / toe box low and slow),
   plus inferred support where the COM is held up but no foot is scheduled
   (:func:`infer_support`: a jump's toe push, a relevé);
3. a second IK pass that holds every stance foot (or toe, at toe-off) flat, at a fixed xy
   and on the floor;
4. temporal Gaussian filtering **before** anything is cropped, with odd-reflection padding
   so that the boundary velocities survive;
5. cubic resampling to the control rate (30 Hz), velocities and accelerations;
6. an inverse-dynamics screen: the root residual wrench that floor contacts in a friction
   pyramid cannot supply (NNLS), and the joint feed-forward torques.

Backward: :func:`qpos_to_joints` (forward kinematics to HumanML3D joints, Y-up) and
:func:`joints_to_features` (via :mod:`simdiff.motion.features`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.interpolate import CubicSpline
from scipy.ndimage import gaussian_filter1d
from scipy.optimize import nnls
from scipy.spatial.transform import Rotation

from simdiff.errors import SimdiffError
from simdiff.sim.humanoid import ModelIndex, hml_to_world, model_index, world_to_hml

HML_FPS: float = 20.0
CONTROL_HZ: float = 30.0

# IK weight of each HumanML3D joint (feet and pelvis matter most for dynamics).
_IK_WEIGHTS = np.ones(22)
_IK_WEIGHTS[[0]] = 3.0
_IK_WEIGHTS[[7, 8, 10, 11]] = 3.0
_IK_WEIGHTS[[12, 15]] = 0.5


@dataclass(frozen=True)
class RetargetConfig:
    """Options of :func:`make_reference`.

    Attributes:
        fps: frame rate of the input joints (HumanML3D: 20).
        control_hz: rate of the produced reference (the tracker's rate, 30).
        ik_polish_iters: Gauss-Newton iterations polishing the closed-form IK (pass 1).
        ik_iters: Gauss-Newton iterations of the stance pass (pass 2), from pass 1.
        ik_damping: Levenberg damping (m²).
        posture_weight: pull of the hinges toward 0 (the upright rest pose).
        contact_height: a foot box is in contact below this sole height (m).
        contact_speed: ... and below this horizontal speed (m/s).
        smooth_sigma: Gaussian filter σ in input frames (0 = off).
        stance_pass: run the second, stance-holding IK pass.
        friction: friction coefficient of the pyramid in the ID screen.
        support_accel: infer support where the schedule has none: at frames whose COM
            vertical acceleration is above ``-support_accel·g`` (the body is not falling
            freely, so something holds it up) the lowest foot box is put in contact and
            pulled to the floor by the stance pass (0 = off). It recovers the toe push of a
            jump's take-off and the relevé of a dancer whose retargeted foot floats.
        support_reach: ... if that box's sole is within this height (m) of the floor.
        contact_spread: ridge weight that spreads the ID screen's contact forces over all
            touching corners (see :func:`inverse_dynamics_screen`; 0: plain NNLS).
        spike_distance: isolated joint samples this far (m) from their neighbours are
            mocap glitches and get replaced (0 = off).
    """

    fps: float = HML_FPS
    control_hz: float = CONTROL_HZ
    ik_polish_iters: int = 3
    ik_iters: int = 4
    ik_damping: float = 1e-4
    posture_weight: float = 2e-3
    contact_height: float = 0.04
    contact_speed: float = 0.6
    smooth_sigma: float = 1.0
    stance_pass: bool = True
    friction: float = 0.8
    contact_spread: float = 1e-3
    support_accel: float = 0.5
    support_reach: float = 0.15
    spike_distance: float = 0.25


@dataclass
class Reference:
    """A retargeted reference at the control rate (K frames, dt = 1/control_hz).

    Attributes:
        qpos: (K, nq) joint positions (root pos m, root quat wxyz, 69 hinges rad).
        qvel: (K, nv); qacc: (K, nv).
        contact: (K, 4) bool reference contact of (L heel box, L toe, R heel box, R toe).
        com: (K, 3) whole-body COM (m, world); com_vel: (K, 3) m/s.
        body_pos: (K, 22, 3) world positions of the HumanML3D joints after retargeting.
        tau_ff: (K, 69) inverse-dynamics joint torques with reference contacts (N·m).
        root_residual: (K, 6) root wrench the contacts cannot supply (force N, torque N·m).
        dt: control period (s); n_in: input frame count; fps_in: input rate.
        ground_shift: metres added to the height to put the stance feet on the floor.
        ik_error: (T,) mean IK joint error per input frame (m).
    """

    qpos: np.ndarray
    qvel: np.ndarray
    qacc: np.ndarray
    contact: np.ndarray
    com: np.ndarray
    com_vel: np.ndarray
    body_pos: np.ndarray
    tau_ff: np.ndarray
    root_residual: np.ndarray
    dt: float
    n_in: int
    fps_in: float
    ground_shift: float = 0.0
    ik_error: np.ndarray = field(default_factory=lambda: np.zeros(0))

    @property
    def num_frames(self) -> int:
        return int(self.qpos.shape[0])

    @property
    def duration(self) -> float:
        """Length in seconds (first to last frame)."""
        return (self.n_in - 1) / self.fps_in

    def feasibility(self, mass: float, gravity: float = 9.81) -> dict[str, float]:
        """Summary of the ID screen: root residual force / (m g) and torque (N·m)."""
        f = np.linalg.norm(self.root_residual[:, :3], axis=1) / (mass * abs(gravity))
        t = np.linalg.norm(self.root_residual[:, 3:], axis=1)
        return {
            "force_median_mg": float(np.median(f)),
            "force_p90_mg": float(np.percentile(f, 90)),
            "frac_over_0.2mg": float(np.mean(f > 0.2)),
            "torque_median_nm": float(np.median(t)),
        }


# --------------------------------------------------------------------------------------
# forward kinematics
# --------------------------------------------------------------------------------------


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


# --------------------------------------------------------------------------------------
# IK
# --------------------------------------------------------------------------------------


@dataclass
class _Task:
    """An extra IK task: hold body ``body`` at ``pos`` (world) and, if given, at rotation ``rot``."""

    body: int
    pos: np.ndarray
    rot: np.ndarray | None
    weight: float


class _IK:
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
        J = np.cross(axes[None, 3:], p[:, None, :] - anchors[None, 3:])  # (22, nv-3, 3)
        out = np.zeros((22, 3, self.nv))
        out[:, :, 3:] = np.swapaxes(J, 1, 2) * self.mask[:, None, 3:]
        out[:, [0, 1, 2], [0, 1, 2]] = 1.0
        return out.reshape(66, self.nv)

    def solve(self, q: np.ndarray, target: np.ndarray, iters: int, tasks: list[_Task] = ()) -> tuple[np.ndarray, float]:
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


def ik_sequence(model, target: np.ndarray, cfg: RetargetConfig, tasks: list[list[_Task]] | None = None,
                init: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Per-frame IK: closed-form, then Gauss-Newton polishing.

    Args:
        target: (T, 22, 3) world joint positions.
        tasks: optional per-frame extra tasks.
        init: optional (T, nq) starting solution; default the closed-form IK of ``target``
            (:func:`simdiff.sim.ik.analytic_ik`).
    Returns:
        qpos (T, nq) and the mean joint error per frame (T,) in metres.
    """
    from simdiff.sim.ik import analytic_ik

    ik = _IK(model, cfg)
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


# --------------------------------------------------------------------------------------
# contacts, stance pass
# --------------------------------------------------------------------------------------


def _box_bottom_corners(model, data, geom: int) -> np.ndarray:
    """(4, 3) world positions of the 4 lowest corners of box geom ``geom``."""
    size = model.geom_size[geom]
    signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], dtype=float)
    local = signs * size
    world = data.geom_xpos[geom] + local @ data.geom_xmat[geom].reshape(3, 3).T
    return world[np.argsort(world[:, 2])[:4]]


def _foot_geoms(model) -> list[int]:
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
    geoms = _foot_geoms(model)
    h = np.zeros((qpos.shape[0], 4))
    xy = np.zeros((qpos.shape[0], 4, 2))
    for t in range(qpos.shape[0]):
        d.qpos[:] = qpos[t]
        mujoco.mj_kinematics(model, d)
        for k, g in enumerate(geoms):
            c = _box_bottom_corners(model, d, g)
            h[t, k] = c[:, 2].min()
            xy[t, k] = d.geom_xpos[g, :2]
    return h, xy


def _box_speed(xy: np.ndarray, fps: float) -> np.ndarray:
    """(T, 4) horizontal speed (m/s) of the foot boxes from their centres (T, 4, 2)."""
    return np.linalg.norm(np.gradient(xy, axis=0) * fps, axis=-1)


def contact_schedule(height: np.ndarray, xy: np.ndarray, fps: float, cfg: RetargetConfig) -> np.ndarray:
    """(T, 4) bool: a foot box touches when low (< contact_height) and slow (< contact_speed)."""
    speed = _box_speed(xy, fps)
    c = (height < cfg.contact_height) & (speed < cfg.contact_speed)
    # a one-frame gap or blip is noise
    for k in range(4):
        col = c[:, k]
        for t in range(1, len(col) - 1):
            if col[t - 1] == col[t + 1] != col[t]:
                col[t] = col[t - 1]
    return c


def infer_support(contact: np.ndarray, height: np.ndarray, xy: np.ndarray, com_z: np.ndarray, fps: float,
                  accel: float, reach: float, max_speed: float = 0.6, gravity: float = 9.81) -> np.ndarray:
    """(T, 4) bool: foot boxes that must carry the body although the schedule has none down.

    A frame is *supported* when the smoothed COM vertical acceleration exceeds
    ``-accel·gravity`` (m/s²): a body in free fall accelerates at -g, so anything clearly
    above that needs a floor force. At supported frames without any scheduled contact, the
    lowest box is added if its sole is below ``reach`` (m) and it moves slower than
    ``max_speed`` (m/s, horizontal; a sliding foot is not a support). Contacts are only
    added, never removed.

    Args:
        contact: (T, 4) schedule from heights; height: (T, 4) sole heights (m);
        xy: (T, 4, 2) box centres (m); com_z: (T,) COM height (m); fps: frame rate.
    """
    if accel <= 0 or len(com_z) < 5:
        return np.zeros_like(contact)
    from scipy.signal import savgol_filter

    # quadratic fits over 5 frames (0.25 s at 20 fps), also at the ends: exact for free fall
    az = savgol_filter(com_z, 5, 2, deriv=2, delta=1.0 / fps, mode="interp")
    need = (az > -accel * gravity) & ~contact.any(axis=1)
    low = height.argmin(axis=1)
    idx = np.arange(len(low))
    speed = _box_speed(xy, fps)[idx, low]
    out = np.zeros_like(contact)
    rows = np.flatnonzero(need & (height[idx, low] < reach) & (speed < max_speed))
    out[rows, low[rows]] = True
    return out


def ground_level(height: np.ndarray, xy: np.ndarray, fps: float, still_speed: float = 0.3) -> float:
    """Floor height (m) of a motion from its foot-box sole heights (T, 4) and centres (T, 4, 2).

    The median sole height of the lowest box over the frames where that box is still
    (horizontal speed below ``still_speed``): a planted foot is on the floor, whatever the
    capture's own zero. Falls back to the 10th percentile of the lowest sole when fewer than
    5 frames are still (a motion that never plants a foot).
    """
    low_box = height.argmin(axis=1)
    low = height[np.arange(len(height)), low_box]
    speed = _box_speed(xy, fps)[np.arange(len(height)), low_box]
    still = speed < still_speed
    if still.sum() >= 5:
        return float(np.median(low[still]))
    return float(np.percentile(low, 10))


def _com_height(model, qpos: np.ndarray) -> np.ndarray:
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


def _intervals(mask: np.ndarray) -> list[tuple[int, int]]:
    """Half-open [start, end) runs of True."""
    out, start = [], None
    for t, v in enumerate(mask):
        if v and start is None:
            start = t
        elif not v and start is not None:
            out.append((start, t))
            start = None
    if start is not None:
        out.append((start, len(mask)))
    return out


def _stance_tasks(model, qpos: np.ndarray, contact: np.ndarray, weight: float = 20.0,
                  max_tilt: float = np.deg2rad(12.0), reach: np.ndarray | None = None) -> list[list[_Task]]:
    """Per-frame tasks that hold each touching foot box flat, on the floor, at a fixed xy.

    Only frames where the box is nearly flat already (tilt below ``max_tilt``) are held: a
    heel rising at toe-off or a toe coming down at heel strike keeps its own pitch (forcing
    it flat would pull the whole body out of shape). The hold's weight ramps over the first
    and last 2 frames of an interval. Boxes marked in ``reach`` (T, 4) (inferred support, see
    :func:`infer_support`) get a position task that lowers them, tilt kept, until their lowest
    corner touches the floor.
    """
    import mujoco

    d = mujoco.MjData(model)
    names = ("L_Ankle", "L_Toe", "R_Ankle", "R_Toe")
    bodies = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, n) for n in names]
    # flat-pose height of each body origin above the floor
    d.qpos[:] = model.qpos0
    mujoco.mj_kinematics(model, d)
    geoms = _foot_geoms(model)
    rest_h = [d.xpos[b][2] - _box_bottom_corners(model, d, g)[:, 2].min() for b, g in zip(bodies, geoms)]
    pos = np.zeros((qpos.shape[0], 4, 3))
    yaw = np.zeros((qpos.shape[0], 4))
    flat = np.zeros((qpos.shape[0], 4), dtype=bool)
    for t in range(qpos.shape[0]):
        d.qpos[:] = qpos[t]
        mujoco.mj_kinematics(model, d)
        for k, b in enumerate(bodies):
            pos[t, k] = d.xpos[b]
            R = d.xmat[b].reshape(3, 3)
            yaw[t, k] = np.arctan2(R[1, 0], R[0, 0])
            flat[t, k] = R[2, 2] > np.cos(max_tilt)
    tasks: list[list[_Task]] = [[] for _ in range(qpos.shape[0])]
    for k, b in enumerate(bodies):
        for s, e in _intervals(contact[:, k] & flat[:, k]):
            p = np.median(pos[s:e, k], axis=0)
            p[2] = rest_h[k]
            y = float(np.angle(np.mean(np.exp(1j * yaw[s:e, k]))))
            R = Rotation.from_euler("z", y).as_matrix()
            for t in range(s, e):  # ramp in and out over 2 frames: no jump when a hold starts
                ramp = min(1.0, (t - s + 1) / 2, (e - t) / 2)
                tasks[t].append(_Task(b, p, R, weight * ramp))
    if reach is not None:
        for k, (b, g) in enumerate(zip(bodies, geoms)):
            for t in np.flatnonzero(reach[:, k]):
                d.qpos[:] = qpos[t]
                mujoco.mj_kinematics(model, d)
                drop = _box_bottom_corners(model, d, g)[:, 2].min()
                tasks[t].append(_Task(b, d.xpos[b] - np.array([0.0, 0.0, drop]), None, weight))
    return tasks


# --------------------------------------------------------------------------------------
# filtering and resampling
# --------------------------------------------------------------------------------------


def _despike(joints: np.ndarray, distance: float) -> np.ndarray:
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


def _smooth(x: np.ndarray, sigma: float) -> np.ndarray:
    """Gaussian filter along axis 0 with odd-reflection padding (keeps boundary velocity)."""
    if sigma <= 0 or x.shape[0] < 3:
        return x
    pad = min(int(np.ceil(4 * sigma)), x.shape[0] - 1)
    head = 2 * x[:1] - x[1 : pad + 1][::-1]
    tail = 2 * x[-1:] - x[-pad - 1 : -1][::-1]
    y = gaussian_filter1d(np.concatenate([head, x, tail], 0), sigma, axis=0, mode="nearest")
    return y[pad : pad + x.shape[0]]


def _continuous_quats(q: np.ndarray) -> np.ndarray:
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
    x[:, 3:7] = _continuous_quats(x[:, 3:7])
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


# --------------------------------------------------------------------------------------
# inverse-dynamics screen
# --------------------------------------------------------------------------------------


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
    geoms = _foot_geoms(m)
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
                for c in _box_bottom_corners(m, d, g):
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


# --------------------------------------------------------------------------------------
# the whole forward conversion
# --------------------------------------------------------------------------------------


def make_reference(model, joints: np.ndarray, cfg: RetargetConfig = RetargetConfig(),
                   gravity: float | None = None) -> Reference:
    """HumanML3D joints → a tracking reference at the control rate.

    Args:
        model: the humanoid (:func:`simdiff.sim.humanoid.load_model`).
        joints: (T, 22, 3) HumanML3D joints, metres, Y-up, ``cfg.fps`` frames per second.
        gravity: vertical gravity (m/s², negative) under which the inverse-dynamics screen and
            the feed-forward torques are computed; None: the model's own ``opt.gravity``.
            The tracker is told g_z (it plans with the world's gravity), not the wind.
    Returns:
        A :class:`Reference` (world frame, Z-up).
    Raises:
        SimdiffError: bad shape, too short, or non-finite joints.
    """
    import mujoco

    joints = np.asarray(joints, dtype=np.float64)
    if joints.ndim != 3 or joints.shape[1:] != (22, 3):
        raise SimdiffError(f"expected joints of shape (T, 22, 3), got {joints.shape}")
    if joints.shape[0] < 4:
        raise SimdiffError(f"motion too short to track: {joints.shape[0]} frames (need ≥ 4)")
    if not np.all(np.isfinite(joints)):
        raise SimdiffError("motion contains non-finite joint positions")
    target = hml_to_world(_despike(joints, cfg.spike_distance))
    fps = cfg.fps

    # 1. per-frame IK
    q1, err = ik_sequence(model, target, cfg)
    # 2. ground alignment + contact schedule
    h, xy = foot_heights(model, q1)
    shift = -ground_level(h, xy, fps)
    q1[:, 2] += shift
    h += shift
    contact = contact_schedule(h, xy, fps, cfg)
    reach = None
    if cfg.support_accel > 0:
        reach = infer_support(contact, h, xy, _com_height(model, q1), fps, cfg.support_accel, cfg.support_reach,
                              cfg.contact_speed)
        contact = contact | reach
    q = q1
    # 3. stance pass
    if cfg.stance_pass and contact.any():
        tasks = _stance_tasks(model, q1, contact, reach=reach)
        q, err = ik_sequence(model, target + np.array([0.0, 0.0, shift]), cfg, tasks=tasks, init=q1)
    # 4. smoothing (before any cropping; odd-reflection keeps the boundary velocity)
    qs = q.copy()
    qs[:, 3:7] = _continuous_quats(qs[:, 3:7])
    qs = _smooth(qs, cfg.smooth_sigma)
    qs[:, 3:7] /= np.linalg.norm(qs[:, 3:7], axis=1, keepdims=True)
    # 5. resampling
    dt = 1.0 / cfg.control_hz
    qpos = resample_qpos(qs, fps, cfg.control_hz)
    qvel = finite_velocity(model, qpos, dt)
    qacc = np.gradient(qvel, dt, axis=0) if qpos.shape[0] > 1 else np.zeros_like(qvel)
    K = qpos.shape[0]
    t_in = np.arange(joints.shape[0]) / fps
    t_out = np.arange(K) * dt
    idx = np.clip(np.round(t_out * fps).astype(int), 0, joints.shape[0] - 1)
    contact_k = contact[idx]
    # COM and joint positions
    d = mujoco.MjData(model)
    ix = model_index(model)
    com = np.zeros((K, 3))
    body = np.zeros((K, 22, 3))
    for t in range(K):
        d.qpos[:] = qpos[t]
        mujoco.mj_kinematics(model, d)
        mujoco.mj_comPos(model, d)
        com[t] = d.subtree_com[ix.pelvis]
        body[t] = d.xpos[ix.hml_bodies]
    com_vel = np.gradient(com, dt, axis=0) if K > 1 else np.zeros_like(com)
    # 6. ID screen
    saved = model.opt.gravity.copy()
    if gravity is not None:
        model.opt.gravity[:] = (0.0, 0.0, gravity)
    try:
        res, tau = inverse_dynamics_screen(model, qpos, qvel, qacc, contact_k, cfg.friction, cfg.contact_spread)
    finally:
        model.opt.gravity[:] = saved
    del t_in
    return Reference(
        qpos=qpos, qvel=qvel, qacc=qacc, contact=contact_k, com=com, com_vel=com_vel, body_pos=body,
        tau_ff=tau, root_residual=res, dt=dt, n_in=joints.shape[0], fps_in=fps, ground_shift=shift,
        ik_error=err,
    )
