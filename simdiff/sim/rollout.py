"""One physics rollout: a tracker follows a reference under φ, with the gated root residual.

Physics at 450 Hz (``model.opt.timestep``), control at the reference rate (30 Hz: 15 physics
steps per control step). Each physics step is ``mj_step1`` (positions, contacts), residual
wrench from the current contacts, ``mj_step2`` (forces, integration).

Failure: a fall (head below ``head_ratio`` of the reference head height, or the mean joint
error after removing the COM offset above ``max_error`` m), or MuJoCo
instability (a warning or a non-finite state), in which case the rollout is marked failed
and must not be used as data.

Fall recovery (:class:`RecoveryConfig`): the full physics state is saved at every control
frame. When the character falls, the rollout rewinds ``window`` control frames and
re-simulates from there with the next alternative tracker setting for ``hold`` frames, then
hands back to the main tracker. Only the committed trajectory is returned (states, residual
log); the discarded attempts count in ``cpu_s``. No force is added: the alternatives only
choose other PD targets, so every physics invariant holds as without recovery.

Flights that follow gravity (``flight``, :mod:`simdiff.sim.flight`): the reference frame of
each control step comes from a :class:`FlightClock`, which waits while the simulation flies
longer than the mocap (low g) and jumps to the landing frame when it lands early (high g);
the rollout then has as many control steps as it needs (``ref_frames`` logs the alignment).
Without it the clock is the reference's own (one frame per control step).
"""

from __future__ import annotations

import copy
import time
from dataclasses import dataclass, field, replace

import numpy as np

from simdiff.sim.retarget.config import Reference
from simdiff.sim.env import Environment
from simdiff.sim.flight import FlightClock, FlightConfig
from simdiff.sim.humanoid import ModelIndex, model_index
from simdiff.sim.residual import ResidualConfig, RootResidual
from simdiff.sim.strength import StrengthConfig, apply_strength, scale_balance, scale_residual
from simdiff.sim.tracker import BalanceConfig, PDTracker, PDTrackerConfig, Tracker


@dataclass(frozen=True)
class FallConfig:
    """Fall detection.

    Attributes:
        head_ratio: fall when head height < head_ratio × reference head height ...
        min_ref_head: ... and the reference head is above this (m) (lying motions excepted).
        max_error: fall when the mean joint error, COM offset removed, exceeds this (m).
        pose_only: remove the whole COM offset (also the vertical one) before that test, so
            that it judges the pose; a body that flies lower or higher than the reference
            (a weaker take-off, another gravity) is not a fall, a collapse still fails the
            head test. False: remove the horizontal offset only.
    """

    head_ratio: float = 0.5
    min_ref_head: float = 0.6
    max_error: float = 0.35
    pose_only: bool = True


def _default_variants() -> tuple[PDTrackerConfig, ...]:
    return (
        PDTrackerConfig(lead=1.0, balance=BalanceConfig(step_gain=0.5)),
        PDTrackerConfig(lead=2.0, balance=BalanceConfig(kd_xy=10.0)),
        PDTrackerConfig(lead=1.5, clearance=0.4, balance=BalanceConfig(kp_rot=1200.0)),
    )


@dataclass(frozen=True)
class RecoveryConfig:
    """Fall recovery by rewinding and re-simulating a window with another tracker setting.

    Attributes:
        window: control frames to rewind before the frame where the fall was detected.
        hold: control frames, from the rewind point, during which the alternative tracker acts.
        max_retries: rewinds per rollout (0 disables recovery).
        variants: alternative :class:`PDTrackerConfig` settings, tried in turn (cyclically).
    """

    window: int = 12
    hold: int = 30
    max_retries: int = 6
    variants: tuple[PDTrackerConfig, ...] = field(default_factory=_default_variants)


@dataclass
class RolloutResult:
    """What one rollout produced.

    Attributes:
        status: ``"ok"``, ``"fell"`` or ``"unstable"``.
        fall_time: time of the fall / instability (s) or None.
        qpos: (S+1, nq) state at every physics step (S steps simulated).
        residual: (S, 6) applied residual wrench (world force N, torque N·m) per physics step.
        support: (S,) a foot/hand touched the floor at that step; airborne: (S,) no floor contact at all.
        violations: physics-invariant violations found by the audit (empty = none).
        cpu_s: CPU seconds of the stepping loop (rewound attempts included).
        timestep: physics step (s); mass: kg; gravity: |g_z|.
        recoveries: how many times the rollout rewound after a fall.
        ref_frames: (N+1,) reference frame aimed at by each control step of the committed
            trajectory (the identity without a flight clock).
        control_dt: control period (s).
    """

    status: str
    fall_time: float | None
    qpos: np.ndarray
    residual: np.ndarray
    support: np.ndarray
    airborne: np.ndarray
    violations: list[str] = field(default_factory=list)
    cpu_s: float = 0.0
    timestep: float = 1.0 / 450.0
    mass: float = 72.0
    gravity: float = 9.81
    recoveries: int = 0
    ref_frames: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))
    control_dt: float = 1.0 / 30.0

    @property
    def success(self) -> bool:
        return self.status == "ok"

    def residual_stats(self) -> dict[str, float]:
        """Mean/peak residual force as a fraction of m·g and in N, and torque in N·m (over all steps)."""
        if self.residual.shape[0] == 0:
            return {"force_mean_mg": 0.0, "force_mean_n": 0.0, "force_peak_mg": 0.0, "torque_mean_nm": 0.0, "torque_peak_nm": 0.0,
                    "airborne_frac": 0.0, "airborne_force_max_n": 0.0}
        f = np.linalg.norm(self.residual[:, :3], axis=1) / (self.mass * self.gravity)
        t = np.linalg.norm(self.residual[:, 3:], axis=1)
        air = self.airborne
        return {
            "force_mean_mg": float(f.mean()),
            "force_mean_n": float(f.mean() * self.mass * self.gravity),
            "force_peak_mg": float(f.max()),
            "torque_mean_nm": float(t.mean()),
            "torque_peak_nm": float(t.max()),
            "airborne_frac": float(air.mean()),
            "airborne_force_max_n": float(np.abs(self.residual[air]).max()) if air.any() else 0.0,
        }


def _unstable(mujoco, data) -> bool:
    w = data.warning
    bad = (mujoco.mjtWarning.mjWARN_BADQACC, mujoco.mjtWarning.mjWARN_BADQVEL, mujoco.mjtWarning.mjWARN_BADQPOS)
    if any(w[int(b)].number > 0 for b in bad):
        return True
    return not (np.all(np.isfinite(data.qpos)) and np.all(np.isfinite(data.qvel)))


def rollout(
    model,
    reference: Reference,
    env: Environment = Environment(),
    tracker: Tracker | None = None,
    residual: ResidualConfig = ResidualConfig(),
    fall: FallConfig = FallConfig(),
    *,
    stop_on_fall: bool = True,
    audit: bool = False,
    recovery: RecoveryConfig | None = None,
    flight: FlightConfig | None = None,
    strength: StrengthConfig | None = StrengthConfig(),
    tracker_config: PDTrackerConfig | None = None,
) -> RolloutResult:
    """Simulate the reference under ``env`` with ``tracker`` and the gated residual.

    Args:
        model: the humanoid; it is copied, the caller's model is not modified.
        reference: from :func:`simdiff.sim.retarget.make_reference`.
        env: φ (validated by the caller).
        tracker: default :class:`PDTracker`.
        residual: residual config (``max_force=0`` is strict).
        stop_on_fall: stop at the first fall (otherwise simulate to the end).
        audit: check the physics invariants at every step (see :func:`_audit`).
        recovery: rewind-and-retry on a fall (default None: off; also off without ``stop_on_fall``).
        flight: follow the simulated flights with a :class:`FlightClock` (None: the reference's
            own clock). The default tracker then runs without its landing sync (the clock
            does that job); the rollout may be longer or shorter than the reference.
        strength: actuator kp, kd and force limits × s = max(1, |g_z|/9.81) on the rollout's
            copy of the model, the balance layer of the default tracker and of the
            recovery variants and the residual's torque bound scaled for s
            (:mod:`simdiff.sim.strength`); a tracker passed in is used as given. None: Earth
            strength at every g.
        tracker_config: settings of the default tracker (None: :class:`PDTrackerConfig`'s); its
            landing sync and balance strength are set as for the default.
    Returns:
        A :class:`RolloutResult`.
    """
    import mujoco

    m = copy.copy(model)
    apply_strength(m, env.gravity, strength)
    s = strength.factor(env.gravity) if strength is not None else 1.0
    if strength is not None:
        residual = scale_residual(residual, s, torque=strength.residual_torque, gains=strength.residual_gains)
    ix: ModelIndex = model_index(m)
    env.apply(m, ix.mass)
    d = mujoco.MjData(m)
    d.qpos[:] = reference.qpos[0]
    d.qvel[:] = reference.qvel[0]
    mujoco.mj_forward(m, d)
    clock = FlightClock(reference.contact, 1.0 / reference.dt, flight) if flight is not None else None
    s_bal = s if strength is not None and strength.balance else 1.0
    base = replace(tracker_config or PDTrackerConfig(), landing_sync=clock is None)
    tracker = tracker or PDTracker(scale_balance(base, s_bal))
    tracker.reset(m, d, reference, ix)
    res = RootResidual(residual, m, reference, ix, env.gravity)
    n_sub = int(round(reference.dt / m.opt.timestep))
    K = reference.num_frames
    N = clock.max_steps if clock is not None else K - 1  # most control steps
    S = N * n_sub
    qpos = np.zeros((S + 1, m.nq))
    qpos[0] = d.qpos
    wrench = np.zeros((S, 6))
    support = np.zeros(S, dtype=bool)
    airborne = np.zeros(S, dtype=bool)
    violations: list[str] = []
    status, fall_time = "ok", None
    ref_head = reference.body_pos[:, 15, 2]
    hml = ix.hml_bodies
    p = ix.pelvis
    rec = recovery if (recovery is not None and stop_on_fall and recovery.max_retries > 0
                       and recovery.variants) else None
    spec = int(mujoco.mjtState.mjSTATE_INTEGRATION)
    states = np.zeros((N + 1, mujoco.mj_stateSize(m, spec))) if rec is not None else None
    clocks: dict[int, FlightClock] = {}
    alternates: dict[int, Tracker] = {}
    override: tuple[int, int, int] | None = None  # (first frame, end frame, variant)
    retries = 0
    step = 0
    k = 0  # reference frame
    n = 0  # control step
    frames = [0]
    t0 = time.process_time()
    while (clock is None and k < K - 1) or (clock is not None and not clock.done):
        if states is not None:
            mujoco.mj_getState(m, d, states[n], spec)
            if clock is not None:
                clocks[n] = clock.snapshot()
        active = tracker
        if override is not None and override[0] <= n < override[1]:
            v = override[2]
            if v not in alternates:
                cfg = scale_balance(rec.variants[v], s_bal)
                if clock is not None:
                    cfg = replace(cfg, landing_sync=False)
                alternates[v] = PDTracker(cfg)
                alternates[v].reset(m, d, reference, ix)
            active = alternates[v]
        d.ctrl[:] = active.act(d, k)
        step = n * n_sub
        for j in range(n_sub):
            mujoco.mj_step1(m, d)
            support[step] = held = res.sim_support(d)
            w = res.wrench(d, d.time if clock is None else k * reference.dt + j * m.opt.timestep, held)
            d.xfrc_applied[p] = w
            wrench[step] = w
            airborne[step] = d.ncon == 0
            mujoco.mj_step2(m, d)
            if audit:
                violations.extend(_audit(m, d, ix, env, w, airborne[step], step))
            step += 1
            qpos[step] = d.qpos
        if _unstable(mujoco, d):
            status, fall_time = "unstable", d.time
            break
        # fall detection at the control rate, against the frame of the next step
        if clock is not None:
            mujoco.mj_subtreeVel(m, d)
            kk = clock.advance(d.ncon > 0, float(d.subtree_linvel[p, 2]))
        else:
            kk = k + 1
        head = d.xpos[ix.head, 2]
        if ref_head[kk] > fall.min_ref_head and head < fall.head_ratio * ref_head[kk]:
            status, fall_time = "fell", d.time
        else:
            off = d.subtree_com[p] - reference.com[kk]
            if not fall.pose_only:
                off[2] = 0.0
            err = np.linalg.norm(d.xpos[hml] - off - reference.body_pos[kk], axis=1).mean()
            if err > fall.max_error:
                status, fall_time = "fell", d.time
        if status == "fell" and rec is not None and retries < rec.max_retries:
            start = max(0, n + 1 - rec.window)
            override = (start, start + rec.hold, retries % len(rec.variants))
            retries += 1
            mujoco.mj_setState(m, d, states[start], spec)
            mujoco.mj_forward(m, d)
            status, fall_time = "ok", None
            n = start
            del frames[start + 1:]
            k = frames[start]
            if clock is not None:
                clock = clocks[start].snapshot()
            continue
        if status != "ok" and stop_on_fall:
            frames.append(kk)
            break
        n += 1
        k = kk
        frames.append(k)
    cpu = time.process_time() - t0
    if status == "fell" and not stop_on_fall:
        pass
    return RolloutResult(
        status=status, fall_time=fall_time, qpos=qpos[: step + 1], residual=wrench[:step], support=support[:step],
        airborne=airborne[:step], violations=violations, cpu_s=cpu, timestep=float(m.opt.timestep), mass=ix.mass,
        gravity=abs(env.gravity), recoveries=retries, ref_frames=np.asarray(frames[: step // n_sub + 1], dtype=int),
        control_dt=float(reference.dt),
    )


def _audit(m, d, ix: ModelIndex, env: Environment, w: np.ndarray, airborne: bool, step: int) -> list[str]:
    """Physics invariants of one step; returns messages for the violated ones.

    * no generalised applied force (``qfrc_applied`` = 0);
    * no Cartesian force on any body but the pelvis, whose wrench equals the logged residual;
    * the residual is exactly zero when no geom touches the floor (airborne);
    * gravity vector equals φ (g_z and the mass-distributed wind), no fluid/wind options;
    * no actuator or passive force on the 6 root dofs.
    """
    out = []
    if np.any(d.qfrc_applied != 0):
        out.append(f"step {step}: qfrc_applied non-zero")
    others = np.delete(d.xfrc_applied, ix.pelvis, axis=0)
    if np.any(others != 0):
        out.append(f"step {step}: xfrc_applied on a body other than the pelvis")
    if not np.array_equal(d.xfrc_applied[ix.pelvis], w):
        out.append(f"step {step}: pelvis wrench differs from the logged residual")
    if airborne and np.any(w != 0):
        out.append(f"step {step}: residual non-zero while airborne")
    if not np.allclose(m.opt.gravity, env.gravity_vector(ix.mass), rtol=0, atol=1e-12):
        out.append(f"step {step}: gravity differs from φ")
    if m.opt.density != 0 or m.opt.viscosity != 0 or np.any(m.opt.wind != 0):
        out.append(f"step {step}: fluid/wind options set")
    if np.any(d.qfrc_actuator[:6] != 0) or np.any(d.qfrc_passive[:6] != 0):
        out.append(f"step {step}: actuator/passive force on the root")
    return out
