"""The projection operator P_φ,π(τ): track a kinematic motion under φ, return the rollout.

``project(joints, env) -> (rollout_joints, info)``; ``rollout_joints`` is (T', 22, 3)
float32 HumanML3D joints (Y-up, metres, 20 fps, same horizontal frame as the input; floor at
y = 0 with HumanML3D's convention: a flat planted foot's toe joint on it, see
:data:`simdiff.sim.humanoid.TOE_JOINT_HEIGHT`) with T' = T on
success and the frames up to the fall otherwise. With a flight clock (``flight``) T' is what
the simulation needed: longer when a low-g flight outlasted the mocap's, shorter when a
high-g flight landed early; distances are then taken against the re-timed source. ``info`` is a :class:`ProjectionInfo`.
"""

from __future__ import annotations

import time
from dataclasses import asdict, dataclass, field

import numpy as np

from simdiff.sim.retarget import RetargetConfig, make_reference, qpos_to_world
from simdiff.sim.env import Environment
from simdiff.sim.fallback import FallbackConfig, rollout_sliding
from simdiff.sim.faithfulness import feature_distance, normalized_features, pose_feature_mask
from simdiff.sim.flight import FlightConfig, aligned_source
from simdiff.sim.humanoid import TOE_JOINT_HEIGHT, HumanoidConfig, load_model, model_index, world_to_hml
from simdiff.sim.residual import ResidualConfig
from simdiff.sim.retime import RetimeConfig, better, stretch
from simdiff.sim.rollout import FallConfig, RolloutResult, rollout
from simdiff.sim.strength import StrengthConfig
from simdiff.sim.tracker import PDTrackerConfig, Tracker

SIM_VERSION: int = 4
"""Version of the physics behind :func:`project` with its defaults, recorded with augmented pairs.

1: Earth strength at every gravity. 2: actuators, the tracker's balance layer and
the residual's torque bound scale with max(1, |g_z|/9.81) (:mod:`simdiff.sim.strength`);
identical to 1 at |g_z| ≤ 9.81. 3: also the residual's pelvis-orientation gains (kp_rot × s,
kd_rot × √s); identical to 2 at |g_z| ≤ 9.81. 4: the same physics; the rollout is returned
:data:`simdiff.sim.humanoid.TOE_JOINT_HEIGHT` (12 mm) lower, on HumanML3D's floor (a flat planted
toe joint at y = 0) instead of the soles'. A record without a version is version 1."""


@dataclass
class ProjectionInfo:
    """Per-motion result of :func:`project`.

    Attributes:
        success: tracked to the end without falling or instability.
        status: ``ok`` / ``fell`` / ``unstable``.
        fall_frame: 20-fps frame index of the fall (None on success).
        n_frames: input frames; n_out: rollout frames returned.
        d_l2: mean per-frame L2 distance between reference and rollout features in the
            normalised HumanML3D representation (paper eq. 13); NaN without a normaliser.
        err_mm: mean joint position error (mm, world, over the returned frames).
        err_local_mm: same after removing the horizontal root offset per frame.
        residual: mean/peak residual force (fraction of m·g) and torque (N·m), airborne share.
        feasibility: ID screen of the reference under φ's g_z (root residual it needs,
            fraction of m·|g_z|).
        cpu_s: CPU seconds (retarget + rollout + metrics); sim_cpu_s: rollout only.
        duration_s: motion length (s); env: (g_z, w_x, w_y).
        violations: physics-invariant violations (only when audited).
        d_l2_pose: :func:`simdiff.sim.faithfulness.pose_d_l2` against the re-timed source
            (pose channels only); NaN without a normaliser.
        time_warp: rollout length / source length (1 without a flight clock).
        retime_scale: slow-down of the source this rollout tracked (1: as given; > 1: the
            second, dynamically similar try of :mod:`simdiff.sim.retime`).
        attempts: rollouts simulated (2 when a re-timed or a fallback try was made, 3 with both;
            whichever was kept); ``cpu_s`` and ``sim_cpu_s`` count them all.
        fallback: the rollout returned is the fallback tracker's (:mod:`simdiff.sim.fallback`).
    """

    success: bool
    status: str
    fall_frame: int | None
    n_frames: int
    n_out: int
    d_l2: float
    err_mm: float
    err_local_mm: float
    residual: dict[str, float]
    feasibility: dict[str, float]
    cpu_s: float
    sim_cpu_s: float
    duration_s: float
    env: tuple[float, float, float]
    violations: list[str] = field(default_factory=list)
    d_l2_pose: float = float("nan")
    time_warp: float = 1.0
    retime_scale: float = 1.0
    attempts: int = 1
    fallback: bool = False

    def to_dict(self) -> dict:
        return asdict(self)


def rollout_joints(model, result: RolloutResult, n_frames: int | None, fps: float = 20.0) -> np.ndarray:
    """HumanML3D joints (T', 22, 3) float32 at ``fps`` from the per-step states of a rollout
    (at most ``n_frames``; None: every frame the rollout covers)."""
    dt = result.timestep
    S = result.qpos.shape[0] - 1
    t_end = S * dt
    n = int(np.floor(t_end * fps + 1e-6)) + 1
    if n_frames is not None:
        n = min(n_frames, n)
    idx = np.arange(n) / fps / dt
    lo = np.clip(np.floor(idx + 1e-9).astype(int), 0, S)
    hi = np.clip(lo + 1, 0, S)
    a = np.clip(idx - lo, 0.0, 1.0)[:, None, None]
    ix = model_index(model)
    p_lo = qpos_to_world(model, result.qpos[lo], ix)
    p_hi = qpos_to_world(model, result.qpos[hi], ix)
    return world_to_hml((1 - a) * p_lo + a * p_hi).astype(np.float32)


def d_l2(ref_joints: np.ndarray, out_joints: np.ndarray, normalizer) -> float:
    """Paper eq. 13: mean over frames of ||norm(f_ref) − norm(f_out)||₂ (263-d features).

    Both motions are cut to the common length; fewer than 2 frames gives NaN.
    """
    return feature_distance(normalized_features(ref_joints, out_joints, normalizer))


def project(
    joints: np.ndarray,
    env: Environment = Environment(),
    *,
    model=None,
    tracker: Tracker | None = None,
    residual: ResidualConfig = ResidualConfig(),
    retarget: RetargetConfig = RetargetConfig(),
    fall: FallConfig = FallConfig(),
    normalizer=None,
    force: bool = False,
    audit: bool = False,
    flight: FlightConfig | None = None,
    strength: StrengthConfig | None = StrengthConfig(),
    retime: RetimeConfig | None = None,
    tracker_config: PDTrackerConfig | None = None,
    fallback: FallbackConfig | None = None,
) -> tuple[np.ndarray, ProjectionInfo]:
    """P_φ,π(τ): replay ``joints`` in MuJoCo under ``env`` and return the rollout.

    Args:
        joints: (T, 22, 3) HumanML3D joints, metres, Y-up, 20 fps.
        env: φ; validated (``force`` skips the range check).
        model: humanoid model (default :func:`load_model`).
        tracker: default :class:`simdiff.sim.tracker.PDTracker`.
        residual: ``ResidualConfig(max_force=0)`` is the strict setting.
        normalizer: a :class:`simdiff.motion.normalize.Normalizer` for d_L2 (NaN if None).
        audit: check the physics invariants at every step (slower).
        flight: follow the simulated flights (:class:`simdiff.sim.flight.FlightClock`);
            None: the reference's own clock (output at most as long as the input).
        strength: actuator strength under |g_z| > 9.81 (:mod:`simdiff.sim.strength`; default
            × max(1, |g_z|/9.81); None: Earth strength at every g).
        retime: under |g_z| < 9.81, when the rollout fell or its pose d_L2 exceeds the
            trigger, track the source slowed to the same Froude number as well and keep the
            better rollout (:mod:`simdiff.sim.retime`); None (default): one try.
        tracker_config: settings of the default tracker (None: the default's; the simulated
            finish's: :func:`simdiff.sim.tracker.finish_tracker_config`).
        fallback: when the rollout kept so far fell or its feet slid, a second rollout of the
            motion as given with other tracker settings, and the better of the two is kept
            (:mod:`simdiff.sim.fallback`; None, the default: no second try).
    Returns:
        (rollout joints (T', 22, 3) float32, :class:`ProjectionInfo`).
    """
    env.validate(force=force)
    model = model if model is not None else load_model(HumanoidConfig())
    joints = np.asarray(joints, dtype=np.float64)
    kw = dict(model=model, tracker=tracker, residual=residual, retarget=retarget, fall=fall, normalizer=normalizer,
              audit=audit, flight=flight, strength=strength, tracker_config=tracker_config)
    out, info = _project_once(joints, env, **kw)
    scale = 1.0 if retime is None else retime.scale(env.gravity)
    if scale != 1.0 and retime.should_retry(info.status, info.d_l2_pose):
        out2, info2 = _project_once(stretch(joints, scale).astype(np.float64), env, **kw)
        cpu, sim_cpu = info.cpu_s + info2.cpu_s, info.sim_cpu_s + info2.sim_cpu_s
        if better((info.status, info.d_l2_pose), (info2.status, info2.d_l2_pose)):
            out, info = out2, info2
            info.n_frames = int(joints.shape[0])
            info.time_warp = float(info.n_out / max(joints.shape[0], 1))
            info.retime_scale = float(scale)
        info.cpu_s, info.sim_cpu_s, info.attempts = cpu, sim_cpu, 2
    if fallback is None:
        return out, info
    sliding = rollout_sliding(out)
    if not fallback.should_retry(info.status, sliding):
        return out, info
    out2, info2 = _project_once(joints, env, **{**kw, "tracker_config": fallback.tracker_config})
    cpu, sim_cpu, attempts = info.cpu_s + info2.cpu_s, info.sim_cpu_s + info2.sim_cpu_s, info.attempts + 1
    if better((info.status, sliding), (info2.status, rollout_sliding(out2))):
        out, info = out2, info2
        info.fallback = True
    info.cpu_s, info.sim_cpu_s, info.attempts = cpu, sim_cpu, attempts
    return out, info


def _project_once(joints: np.ndarray, env: Environment, *, model, tracker: Tracker | None, residual: ResidualConfig,
                  retarget: RetargetConfig, fall: FallConfig, normalizer, audit: bool, flight: FlightConfig | None,
                  strength: StrengthConfig | None,
                  tracker_config: PDTrackerConfig | None = None) -> tuple[np.ndarray, ProjectionInfo]:
    """One rollout of ``joints`` (float64, validated φ) and its distances; see :func:`project`."""
    t0 = time.process_time()
    ref = make_reference(model, joints, retarget, gravity=env.gravity)
    res = rollout(model, ref, env, tracker, residual, fall, audit=audit, flight=flight, strength=strength,
                  tracker_config=tracker_config)
    out = rollout_joints(model, res, joints.shape[0] if flight is None else None, retarget.fps)
    if flight is None:
        source = joints[: len(out)]
    else:
        source = aligned_source(joints, res.ref_frames, 1.0 / res.control_dt, retarget.fps, len(out))
    ref_j = source + np.array([0.0, ref.ground_shift, 0.0])
    diff = out - ref_j
    err = float(np.linalg.norm(diff, axis=-1).mean() * 1e3)
    local = diff - diff[:, :1] * np.array([1.0, 0.0, 1.0])
    err_local = float(np.linalg.norm(local, axis=-1).mean() * 1e3)
    fall_frame = None if res.fall_time is None else int(np.floor(res.fall_time * retarget.fps))
    features = normalized_features(source, out, normalizer)  # once for both distances
    dl2 = feature_distance(features)
    dl2_pose = feature_distance(features, pose_feature_mask())
    ix = model_index(model)
    info = ProjectionInfo(
        success=res.success, status=res.status, fall_frame=fall_frame, n_frames=int(joints.shape[0]),
        n_out=int(len(out)), d_l2=dl2, err_mm=err, err_local_mm=err_local, residual=res.residual_stats(),
        feasibility=ref.feasibility(ix.mass, env.gravity), cpu_s=time.process_time() - t0, sim_cpu_s=res.cpu_s,
        duration_s=ref.duration, env=env.as_tuple(), violations=res.violations, d_l2_pose=dl2_pose,
        time_warp=float(len(out) / max(joints.shape[0], 1)),
    )
    # The distances above are taken in the simulator's frame (soles on the floor), as the augmented
    # corpus was filtered; the rollout returned is in HumanML3D's (planted toe joint on the floor).
    out = out.copy()
    out[..., 1] -= TOE_JOINT_HEIGHT
    return out, info
