"""The whole forward conversion: HumanML3D joints → a tracking :class:`Reference`.

1. closed-form IK (:mod:`simdiff.sim.retarget.ik`) of the 22 joint positions, polished by a
   few damped Gauss-Newton iterations per frame (joint ranges clamped, a small posture prior);
2. ground alignment and a contact schedule per foot (heel box / toe box low and slow),
   plus inferred support where the COM is held up but no foot is scheduled
   (:func:`~simdiff.sim.retarget.contacts.infer_support`: a jump's toe push, a relevé);
   with ``anchor_stance`` the body is shifted horizontally so that planted feet stay put
   (:func:`~simdiff.sim.retarget.contacts.stance_anchor_shift`), the lowest foot standing in
   for a planted one where every foot on the floor glides
   (:func:`~simdiff.sim.retarget.contacts.skating_support`);
3. a second IK pass that holds every stance foot (or toe, at toe-off) flat, at a fixed xy
   and on the floor, and with ``swing_clearance`` lifts fast swing feet clear of it
   (:func:`~simdiff.sim.retarget.contacts.swing_lift`);
4. temporal Gaussian filtering **before** anything is cropped, with odd-reflection padding
   so that the boundary velocities survive;
5. cubic resampling to the control rate (30 Hz), velocities and accelerations;
6. an inverse-dynamics screen: the root residual wrench that floor contacts in a friction
   pyramid cannot supply (NNLS), and the joint feed-forward torques.
"""

from __future__ import annotations

import numpy as np

from simdiff.errors import SimdiffError
from simdiff.sim.humanoid import hml_to_world, model_index
from simdiff.sim.retarget.config import Reference, RetargetConfig
from simdiff.sim.retarget.contacts import (contact_schedule, ground_level, infer_support, skating_support,
                                           stance_anchor_shift, stance_tasks, swing_lift)
from simdiff.sim.retarget.dynamics import inverse_dynamics_screen
from simdiff.sim.retarget.filtering import continuous_quats, despike, finite_velocity, resample_qpos, smooth
from simdiff.sim.retarget.ik import ik_sequence
from simdiff.sim.retarget.kinematics import com_height, foot_heights


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
    target = hml_to_world(despike(joints, cfg.spike_distance))
    fps = cfg.fps

    # 1. per-frame IK
    q1, err = ik_sequence(model, target, cfg)
    # 2. ground alignment + contact schedule
    h, xy = foot_heights(model, q1)
    shift = -ground_level(h, xy, fps)
    q1[:, 2] += shift
    h += shift
    contact = contact_schedule(h, xy, fps, cfg)
    if cfg.anchor_stance:
        support = contact | skating_support(contact, h, cfg.contact_height)
        offset = stance_anchor_shift(support, xy)  # (T, 2), world xy
        q1[:, :2] += offset
        xy = xy + offset[:, None]
        target = target.copy()
        target[..., :2] += offset[:, None]
    reach = None
    if cfg.support_accel > 0:
        reach = infer_support(contact, h, xy, com_height(model, q1), fps, cfg.support_accel, cfg.support_reach,
                              cfg.contact_speed)
        contact = contact | reach
    lift = swing_lift(contact, h, xy, fps, cfg.swing_clearance, cfg.contact_speed, 2.0 * cfg.contact_speed)
    q = q1
    # 3. stance pass
    if cfg.stance_pass and (contact.any() or lift.any()):
        tasks = stance_tasks(model, q1, contact, reach=reach, lift=lift if lift.any() else None)
        q, err = ik_sequence(model, target + np.array([0.0, 0.0, shift]), cfg, tasks=tasks, init=q1)
    # 4. smoothing (before any cropping; odd-reflection keeps the boundary velocity)
    qs = q.copy()
    qs[:, 3:7] = continuous_quats(qs[:, 3:7])
    qs = smooth(qs, cfg.smooth_sigma)
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
