"""Trackers: state + reference → 69 PD targets at the control rate (30 Hz).

A :class:`Tracker` only chooses the PD targets (radians) that the humanoid's position servos
hold for one control period (15 physics steps at 450 Hz). A learned policy can implement the
same interface later. The root residual wrench is *not* part of a tracker: it lives in
:mod:`simdiff.sim.residual` and is applied, gated and logged by the rollout.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np

from simdiff.sim.convert import Reference, _foot_geoms
from simdiff.sim.humanoid import ModelIndex


@runtime_checkable
class Tracker(Protocol):
    """The controller interface used by :func:`simdiff.sim.rollout.rollout`."""

    def reset(self, model, data, reference: Reference, index: ModelIndex) -> None:
        """Prepare for a new rollout of ``reference`` (data is at the initial state)."""

    def act(self, data, k: int) -> np.ndarray:
        """PD targets (69,) in radians held during control period k, i.e. [k·dt, (k+1)·dt)."""


@dataclass(frozen=True)
class PDTrackerConfig:
    """Options of :class:`PDTracker`.

    Attributes:
        lead: reference time lead in control periods (targets aim at q_ref(k + lead)).
        feedforward: add the inverse-dynamics torques as a target offset τ_ff / kp.
        velocity_ff: add kd·q̇_ref / kp so that damping acts on the velocity error.
        clearance: extra hip/knee flexion (rad) for a leg whose reference foot is in swing
            while the simulated foot still touches the floor (toe-off / swing clearance).
        target_margin: targets are clipped to the joint range widened by this (rad).
        balance_kp, balance_kd: ankle strategy: stance-ankle pitch/roll offsets (rad per m,
            rad per m/s) from the COM position/velocity error in the heading frame, shared
            between the stance legs.
    """

    lead: float = 0.5
    feedforward: bool = True
    velocity_ff: bool = True
    clearance: float = 0.25
    target_margin: float = 0.3
    balance_kp: float = 1.5
    balance_kd: float = 0.4


class PDTracker:
    """The default tracker: PD targets from the reference with ID feed-forward.

    target = q_ref(k + lead) + (τ_ff + kd q̇_ref) / kp, plus a swing-clearance bias that
    flexes hip, knee and ankle of a leg whose reference foot is airborne but whose simulated
    foot is still on the floor (the trailing foot sticking at toe-off was the main failure of
    the probes' walks).
    """

    def __init__(self, config: PDTrackerConfig = PDTrackerConfig()) -> None:
        self.cfg = config

    def reset(self, model, data, reference: Reference, index: ModelIndex) -> None:
        import mujoco

        self.ref = reference
        self.ix = index
        self.lo = index.jnt_lo - self.cfg.target_margin
        self.hi = index.jnt_hi + self.cfg.target_margin
        self.foot_geoms = _foot_geoms(model)
        names = [mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, i) for i in range(1, model.njnt)]
        self.leg = {
            side: (names.index(f"{side}_Hip_y"), names.index(f"{side}_Knee_y"), names.index(f"{side}_Ankle_y"))
            for side in ("L", "R")
        }
        self.ankle_x = {side: names.index(f"{side}_Ankle_x") for side in ("L", "R")}
        self.model = model
        K = reference.num_frames
        t = np.clip(np.arange(K) + self.cfg.lead, 0, K - 1)
        i0 = np.floor(t).astype(int)
        i1 = np.minimum(i0 + 1, K - 1)
        a = (t - i0)[:, None]
        q = reference.qpos[:, 7:]
        self.q_target = (1 - a) * q[i0] + a * q[i1]
        off = np.zeros_like(self.q_target)
        if self.cfg.feedforward:
            off += reference.tau_ff
        if self.cfg.velocity_ff:
            off += index.kd * reference.qvel[:, 6:]
        self.base = self.q_target + off / index.kp

    def _foot_on_floor(self, data) -> np.ndarray:
        """(4,) whether each foot box (LF, LT, RF, RT) touches the floor now."""
        out = np.zeros(4, dtype=bool)
        if data.ncon:
            g = data.contact.geom[: data.ncon].ravel()
            for k, fg in enumerate(self.foot_geoms):
                out[k] = bool(np.any(g == fg))
        return out

    def act(self, data, k: int) -> np.ndarray:
        k = min(k, self.ref.num_frames - 1)
        target = self.base[k].copy()
        c = self.cfg.clearance
        if c > 0:
            on = self._foot_on_floor(data)
            kn = min(k + 1, self.ref.num_frames - 1)
            for side, cols in (("L", (0, 1)), ("R", (2, 3))):
                ref_swing = not self.ref.contact[kn, cols[0]] and not self.ref.contact[kn, cols[1]]
                if ref_swing and (on[cols[0]] or on[cols[1]]):
                    hip, knee, ankle = self.leg[side]
                    target[hip] -= c
                    target[knee] += 2 * c
                    target[ankle] -= c
        if self.cfg.balance_kp > 0 or self.cfg.balance_kd > 0:
            self._balance(data, k, target)
        return np.clip(target, self.lo, self.hi)

    def _balance(self, data, k: int, target: np.ndarray) -> None:
        """Ankle strategy on the legs whose foot touches the floor."""
        import mujoco

        on = self._foot_on_floor(data)
        stance = [side for side, cols in (("L", (0, 1)), ("R", (2, 3))) if on[cols[0]] or on[cols[1]]]
        if not stance:
            return
        mujoco.mj_subtreeVel(self.model, data)
        p = self.ix.pelvis
        e = data.subtree_com[p] - self.ref.com[k]
        v = data.subtree_linvel[p] - self.ref.com_vel[k]
        x_axis = data.xmat[p].reshape(3, 3)[:, 0]
        fwd = np.array([x_axis[0], x_axis[1], 0.0])
        fwd /= max(np.linalg.norm(fwd), 1e-9)
        left = np.array([-fwd[1], fwd[0], 0.0])
        u = self.cfg.balance_kp * e + self.cfg.balance_kd * v
        share = 1.0 / len(stance)
        for side in stance:
            target[self.leg[side][2]] += share * float(u @ fwd)  # plantarflex when ahead
            target[self.ankle_x[side]] -= share * float(u @ left)  # press the left edge when left
