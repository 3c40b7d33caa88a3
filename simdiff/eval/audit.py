"""Physics audit of one motion: how plausible it is, what it would take, what the simulator makes of it.

Three parts, all for joints (T, 22, 3) in metres, Y-up, 20 fps:

1. kinematic physics metrics (:func:`simdiff.motion.metrics.physics_metrics`): penetration,
   floating, sliding (mm), skate ratio;
2. the inverse-dynamics screen of the reference the tracker would follow
   (:func:`simdiff.sim.retarget.make_reference` on a humanoid whose gravity is φ's, i.e. g_z
   and the mass-distributed wind): per 30 Hz frame, the root wrench that gravity, wind and
   floor contacts in a friction pyramid cannot supply. Force is reported as a fraction of
   m·|g_z| (m = humanoid mass, 72 kg), torque in N·m. The reference is put on the floor
   first (``ground_shift_m``: a motion floating 0.5 m up is lowered 0.5 m), so floating
   shows in the metrics and the shift, not in the residual;
3. tracking it under φ with :func:`simdiff.sim.project.project` (exactly what
   ``simdiff track`` does): success, fall frame, d_L2, tracking error, the residual the
   rollout applied, CPU seconds;
4. the gravity its flights obey (:func:`simdiff.motion.gravity_readout.read_gravity`: the centre of mass's
   parabola over the airborne frames), for the motion and for the rollout, against φ's g_z;
5. its gait (:func:`simdiff.motion.gait.gait_measures`): pelvis and limb speed, cadence, duty factor.
"""

from __future__ import annotations

import copy
import math
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from simdiff.errors import SimdiffError
from simdiff.sim.env import Environment
from simdiff.sim.residual import ResidualConfig

FORCE_THRESHOLD_MG: float = 0.1
"""A frame 'needs external force' when its residual force exceeds this fraction of m·|g_z|."""


@dataclass
class ResidualSeries:
    """The reference's root residual over time (control rate, 30 Hz).

    Attributes:
        t: (K,) time in seconds.
        force_mg: (K,) residual force magnitude as a fraction of m·|g_z|.
        torque_nm: (K,) residual torque magnitude (N·m).
        contact: (K,) a foot box of the reference touches the floor.
    """

    t: np.ndarray
    force_mg: np.ndarray
    torque_nm: np.ndarray
    contact: np.ndarray


@dataclass
class Audit:
    """Result of :func:`audit_motion`.

    Attributes:
        name: a label (the file name in the CLI).
        n_frames: input frames; duration_s: seconds (20 fps).
        env: φ = (g_z, w_x, w_y).
        metrics: penetration, floating (mm), sliding (mm/frame), skate_ratio.
        reference: ID screen summary (see :func:`reference_residual`).
        tracking: the :class:`simdiff.sim.project.ProjectionInfo` fields, or None with ``track=False``.
        cpu_s: CPU seconds of the whole audit.
        series: the residual over time (not in :meth:`to_dict`).
        root_height: (T,) input pelvis height (m); ``rollout``: (T', 22, 3) rollout joints or None.
        flight, rollout_flight: the gravity read from the motion's and the rollout's flights
            (:func:`simdiff.motion.gravity_readout.read_gravity`), None without a readable flight.
        gait: pelvis_speed, limb_speed (m/s), cadence (steps/min), duty_factor.
    """

    name: str
    n_frames: int
    duration_s: float
    env: tuple[float, float, float]
    metrics: dict[str, float]
    reference: dict[str, float]
    tracking: dict | None
    cpu_s: float
    series: ResidualSeries = field(repr=False)
    root_height: np.ndarray = field(repr=False)
    rollout: np.ndarray | None = field(default=None, repr=False)
    flight: dict[str, float] | None = None
    rollout_flight: dict[str, float] | None = None
    gait: dict[str, float] | None = None

    def to_dict(self) -> dict:
        """JSON-ready summary (NaN → None)."""
        out = {
            "file": self.name, "frames": self.n_frames, "duration_s": self.duration_s, "env": list(self.env),
            "metrics": self.metrics, "reference": self.reference, "tracking": self.tracking, "cpu_s": self.cpu_s,
            "flight": self.flight, "rollout_flight": self.rollout_flight, "gait": self.gait,
        }
        return _clean(out)

    def table(self) -> str:
        """A human-readable report, one quantity per line."""
        return format_table(self)


def _clean(x):
    if isinstance(x, float):
        return None if math.isnan(x) or math.isinf(x) else x
    if isinstance(x, dict):
        return {k: _clean(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_clean(v) for v in x]
    if isinstance(x, np.generic):
        return _clean(x.item())
    return x


def reference_residual(joints: np.ndarray, env: Environment = Environment(), *, model=None,
                       retarget=None) -> tuple[dict[str, float], ResidualSeries]:
    """Inverse-dynamics screen of a motion's tracking reference under φ.

    Args:
        joints: (T, 22, 3) HumanML3D joints, metres, Y-up, 20 fps (T ≥ 4).
        env: φ; gravity and wind enter the inverse dynamics (validated by the caller).
        model: the humanoid (default :func:`simdiff.sim.humanoid.load_model`); not modified.
        retarget: :class:`simdiff.sim.retarget.RetargetConfig`; default: the standard config
            without support inference (``support_accel=0``), so that a foot hovering near
            the floor is judged as the motion has it, not pulled down as the tracker's
            reference repair would.
    Returns:
        (summary, series). Summary keys: ``force_mean_mg``, ``force_p90_mg``,
        ``force_peak_mg`` (fraction of m·|g_z|), ``torque_mean_nm``, ``torque_p90_nm``,
        ``torque_peak_nm``, ``frac_over_0.1mg`` (share of frames above
        :data:`FORCE_THRESHOLD_MG`), ``contact_frac`` (frames with a foot on the floor),
        ``ground_shift_m`` (height added to put the stance feet on the floor), ``ik_error_mm``
        (mean joint error of the retargeting), ``mass_kg``.
    """
    from simdiff.sim.retarget import RetargetConfig, make_reference
    from simdiff.sim.humanoid import load_model, model_index

    base = model if model is not None else load_model()
    m = copy.copy(base)  # the cached model stays at Earth gravity
    mass = model_index(m).mass
    env.apply(m, mass)
    ref = make_reference(m, np.asarray(joints, dtype=np.float64), retarget or RetargetConfig(support_accel=0.0))
    g = abs(env.gravity)
    force = np.linalg.norm(ref.root_residual[:, :3], axis=1) / (mass * g)
    torque = np.linalg.norm(ref.root_residual[:, 3:], axis=1)
    contact = ref.contact.any(axis=1)
    summary = {
        "force_mean_mg": float(force.mean()),
        "force_p90_mg": float(np.percentile(force, 90)),
        "force_peak_mg": float(force.max()),
        "torque_mean_nm": float(torque.mean()),
        "torque_p90_nm": float(np.percentile(torque, 90)),
        "torque_peak_nm": float(torque.max()),
        f"frac_over_{FORCE_THRESHOLD_MG:g}mg": float(np.mean(force > FORCE_THRESHOLD_MG)),
        "contact_frac": float(contact.mean()),
        "ground_shift_m": float(ref.ground_shift),
        "ik_error_mm": float(np.mean(ref.ik_error) * 1e3) if ref.ik_error.size else float("nan"),
        "mass_kg": float(mass),
    }
    series = ResidualSeries(t=np.arange(ref.num_frames) * ref.dt, force_mg=force, torque_nm=torque, contact=contact)
    return summary, series


def audit_motion(joints: np.ndarray, env: Environment = Environment(), *, name: str = "motion",
                 residual: ResidualConfig = ResidualConfig(), track: bool = True, normalizer=None,
                 force: bool = False, progress: bool = False) -> Audit:
    """Audit one motion (see the module docstring).

    Args:
        joints: (T, 22, 3) joints, metres, Y-up, 20 fps, T ≥ 4.
        env: φ; validated here (``force`` skips the range check, gravity must still be < 0).
        name: label for reports.
        residual: root residual bound of the tracking rollout (``max_force=0``: strict).
        track: run the simulator (the slow part); False gives metrics and the ID screen only.
        normalizer: feature normaliser for d_L2 (NaN without one).
        progress: a tqdm bar over the stages on stderr.
    Raises:
        SimdiffError: bad φ, shape, too short or non-finite joints.
    """
    from tqdm.auto import tqdm

    from simdiff.motion.metrics import physics_metrics

    t0 = time.process_time()
    env.validate(force=force)
    joints = np.asarray(joints, dtype=np.float32)
    if joints.ndim != 3 or joints.shape[1:] != (22, 3):
        raise SimdiffError(f"{name}: expected joints of shape (T, 22, 3), got {tuple(joints.shape)}")
    if joints.shape[0] < 4:
        raise SimdiffError(f"{name}: motion too short to audit: {joints.shape[0]} frames (need ≥ 4)")
    if not np.isfinite(joints).all():
        raise SimdiffError(f"{name}: motion contains NaN or infinite joint positions")
    bar = tqdm(total=3 if track else 2, desc=f"audit {name}", unit="stage", disable=not progress, leave=False,
               dynamic_ncols=True)
    metrics = {k: float(v) for k, v in physics_metrics(joints).items()}
    bar.update()
    try:
        summary, series = reference_residual(joints, env)
        bar.update()
        tracking, out = None, None
        if track:
            from simdiff.sim.project import project

            out, info = project(joints, env, residual=residual, normalizer=normalizer, force=force)
    except np.linalg.LinAlgError as exc:  # a degenerate pose (joints coinciding) has no body fit
        bar.close()
        raise SimdiffError(f"{name}: the humanoid cannot be fitted to these joints ({exc}; do joints coincide?)") \
            from None
    if track:
        tracking = info.to_dict()
        tracking.pop("env", None)
        tracking.pop("feasibility", None)  # the Earth-gravity screen; ``reference`` has it under φ
        tracking["fall_s"] = None if info.fall_frame is None else info.fall_frame / 20.0
        tracking["residual_bound_mg"] = residual.max_force
        bar.update()
    bar.close()
    from simdiff.motion.gait import gait_measures
    from simdiff.motion.gravity_readout import read_gravity

    return Audit(
        name=name, n_frames=int(joints.shape[0]), duration_s=(joints.shape[0] - 1) / 20.0, env=env.as_tuple(),
        metrics=metrics, reference=summary, tracking=tracking, cpu_s=time.process_time() - t0, series=series,
        root_height=joints[:, 0, 1].astype(np.float64), rollout=out, flight=read_gravity(joints),
        rollout_flight=read_gravity(out) if out is not None and len(out) >= 2 else None, gait=gait_measures(joints),
    )


# --------------------------------------------------------------------------------------
# reports
# --------------------------------------------------------------------------------------


def _fmt(v: float | None, spec: str) -> str:
    return "n/a" if v is None or (isinstance(v, float) and math.isnan(v)) else format(v, spec)


def format_table(a: Audit) -> str:
    """The human-readable report of :class:`Audit`."""
    g, wx, wy = a.env
    r, m = a.reference, a.metrics
    key = f"frac_over_{FORCE_THRESHOLD_MG:g}mg"
    lines = [
        f"{a.name}: {a.n_frames} frames, {a.duration_s:.2f} s; φ: gravity {g:g} m/s², wind ({wx:g}, {wy:g}) N",
        "  physics metrics (joints, floor y = 0)",
        f"    penetration      {m['penetration']:9.1f} mm",
        f"    floating         {m['floating']:9.1f} mm",
        f"    sliding          {m['sliding']:9.2f} mm/frame",
        f"    skate ratio      {m['skate_ratio']:9.3f}",
        "  reference: inverse-dynamics root residual (what gravity, wind and floor contacts cannot supply)",
        f"    force            mean {r['force_mean_mg']:.3f}   p90 {r['force_p90_mg']:.3f}   "
        f"peak {r['force_peak_mg']:.3f}   × m·|g| ({r['mass_kg']:.0f} kg)",
        f"    torque           mean {r['torque_mean_nm']:.0f}   p90 {r['torque_p90_nm']:.0f}   "
        f"peak {r['torque_peak_nm']:.0f}   N·m",
        f"    frames > {FORCE_THRESHOLD_MG:g} m·g   {100 * r[key]:9.1f} %",
        f"    foot contact     {100 * r['contact_frac']:9.1f} % of frames",
        f"    ground shift     {1e3 * r['ground_shift_m']:+9.0f} mm (to put the stance feet on the floor)",
        f"    IK error         {_fmt(r['ik_error_mm'], '9.1f')} mm",
    ]
    t = a.tracking
    if t is None:
        lines.append("  tracking: skipped (--no-track)")
    else:
        res = t["residual"]
        if t["success"]:
            result = "tracked to the end"
        else:
            result = f"{t['status'].upper()} at frame {t['fall_frame']} ({_fmt(t['fall_s'], '.2f')} s)"
        lines += [
            f"  tracking under φ (PD tracker, residual bound {t['residual_bound_mg']:g} m·g)",
            f"    result           {result}",
            f"    d_L2             {_fmt(t['d_l2'], '9.3f')}",
            f"    tracking error   {t['err_mm']:9.1f} mm (root-relative {t['err_local_mm']:.1f} mm) "
            f"over {t['n_out']} frames",
            f"    residual applied force mean {res['force_mean_mg']:.3f} / peak {res['force_peak_mg']:.3f} m·g, "
            f"torque {res['torque_mean_nm']:.0f} / {res['torque_peak_nm']:.0f} N·m, airborne {100 * res['airborne_frac']:.0f} %",
            f"    CPU              {t['cpu_s']:9.2f} s ({t['cpu_s'] / max(t['duration_s'], 1e-9):.2f} s per motion second)",
        ]
    lines.append(f"  flights: gravity of the centre of mass's parabola (φ asks {g:g} m/s²)")
    lines.append(f"    motion           {_flight(a.flight)}")
    if a.tracking is not None:
        lines.append(f"    rollout          {_flight(a.rollout_flight)}")
    if a.gait is not None:
        gait = a.gait
        lines += ["  gait (a foot is down within 5 cm of its floor)",
                  f"    pelvis speed     {gait['pelvis_speed']:9.2f} m/s   limb speed {gait['limb_speed']:.2f} m/s "
                  "(wrists and ankles relative to the pelvis)",
                  f"    cadence          {gait['cadence']:9.0f} steps/min   duty factor {gait['duty_factor']:.2f}"]
    lines.append(f"  audit CPU          {a.cpu_s:9.2f} s")
    return "\n".join(lines)


def _flight(reading: dict[str, float] | None) -> str:
    if reading is None:
        return "no flight long enough to read (5 airborne frames)"
    n = int(reading["flights"])
    return (f"{reading['gravity']:9.2f} m/s² over {int(reading['frames'])} airborne frames in {n} "
            f"flight{'s' if n != 1 else ''}, fit error ≤ {1e3 * reading['rmse_m']:.0f} mm")


def _spans(mask: np.ndarray) -> list[tuple[int, int]]:
    """Half-open runs [start, end) of True in a 1-D bool array."""
    m = np.concatenate([[False], np.asarray(mask, dtype=bool), [False]])
    d = np.diff(m.astype(int))
    return list(zip(np.flatnonzero(d == 1), np.flatnonzero(d == -1)))


def plot_audit(a: Audit, path: str | Path, dpi: int = 110) -> Path:
    """Save the audit plot (PNG): residual force and torque over time with the airborne
    phases of the reference shaded, and the root height of the reference vs the rollout.

    Args:
        a: an :class:`Audit`.
        path: output ``.png``; the parent folder is created.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from matplotlib.patches import Patch

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    s = a.series
    fig = Figure(figsize=(8.0, 5.4), dpi=dpi)
    FigureCanvasAgg(fig)
    ax1, ax2 = fig.subplots(2, 1, sharex=True, gridspec_kw={"height_ratios": [1.3, 1.0]})
    dt = float(s.t[1] - s.t[0]) if len(s.t) > 1 else 1 / 30
    for ax in (ax1, ax2):
        for i, j in _spans(~s.contact):
            ax.axvspan(s.t[i] - dt / 2, s.t[min(j, len(s.t)) - 1] + dt / 2, color="#f4c7a1", alpha=0.55, lw=0)
    ax1.plot(s.t, s.force_mg, color="#c0392b", lw=1.6, label="residual force")
    ax1.axhline(FORCE_THRESHOLD_MG, color="#c0392b", lw=0.8, ls="--")
    ax1.set_ylabel("force / (m·|g|)")
    ax1.set_ylim(bottom=0)
    axt = ax1.twinx()
    axt.plot(s.t, s.torque_nm, color="#2c3e50", lw=1.0, alpha=0.7, label="residual torque")
    axt.set_ylabel("torque (N·m)")
    axt.set_ylim(bottom=0)
    handles = [ax1.lines[0], axt.lines[0], Patch(color="#f4c7a1", alpha=0.55, label="no foot contact")]
    ax1.legend(handles=handles, loc="upper right", fontsize=8, framealpha=0.85)
    t_in = np.arange(a.n_frames) / 20.0
    shift = a.reference["ground_shift_m"]
    ax2.plot(t_in, a.root_height + shift, color="#2471a3", lw=1.6, label="reference (on the floor)")
    if abs(shift) > 0.01:
        ax2.plot(t_in, a.root_height, color="#2471a3", lw=1.0, ls=":", label="input")
    if a.rollout is not None:
        t_out = np.arange(len(a.rollout)) / 20.0
        ax2.plot(t_out, a.rollout[:, 0, 1], color="#e67e22", lw=1.6, label="rollout")
        if a.tracking and a.tracking.get("fall_s") is not None:
            ax2.axvline(a.tracking["fall_s"], color="#e67e22", lw=1.0, ls="--")
            ax2.text(a.tracking["fall_s"], ax2.get_ylim()[1], f" {a.tracking['status']}", color="#e67e22",
                     va="top", fontsize=8)
    ax2.set_ylabel("root height (m)")
    ax2.set_xlabel("time (s)")
    ax2.legend(loc="lower right", fontsize=8, framealpha=0.85)
    g, wx, wy = a.env
    r = a.reference
    status = "not tracked" if a.tracking is None else (
        "tracked" if a.tracking["success"] else f"{a.tracking['status']} at {a.tracking['fall_s']:.2f} s")
    fig.suptitle(f"{a.name}   g={g:g} m/s², wind=({wx:g}, {wy:g}) N   residual p90 {r['force_p90_mg']:.2f} m·g, "
                 f"{status}", fontsize=10)
    fig.tight_layout(rect=(0, 0, 1, 0.96))
    from simdiff.fsio import atomic_path

    with atomic_path(path) as tmp:
        fig.savefig(tmp)
    return path
