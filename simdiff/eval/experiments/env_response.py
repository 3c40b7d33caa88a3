"""Environment-response benchmark: generated responses to φ against the simulator's, per motion.

Every method generates each prompt × seed under Earth and under every φ of the grid (the
``env_control`` sweeps: gravity at no wind, w_x and w_y at Earth gravity, each combination and
its single-factor parts; the same noise for every φ). The simulator re-tracks each *Earth*
motion under Earth and under every φ (flights following gravity): the physically right answer
for that motion. :mod:`simdiff.eval.response` turns the pairs into sign agreement, slope ratio
(generated / simulated, bootstrap intervals over prompt × seed units) and, for combinations,
the additivity error against the single-factor effects.

A readout check (``env_control.readout_clips``) validates the gravity measure itself: the split's real jumps are
read as they are (Earth) and re-tracked by the simulator under each gravity of the grid, whose rollouts must read
the gravity they were made under.

The same script scores MDM (env-blind: one generation reused for every φ, so it must score no
response), SimDiff with binary adapters (φ does not reach them either: one generation of the
'simulated' class for every φ), SimDiff (continuous φ adapters) and PhysDiff (projection under φ).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from simdiff.errors import SimdiffError
from simdiff.eval.experiments.config import ModelSpec
from simdiff.eval.experiments.fig5 import conditions
from simdiff.eval.experiments.report import fmt_env, save_figure
from simdiff.eval.experiments.runner import EARTH, FPS, RowPlan, Runner, safe
from simdiff.eval.response import additivity, check_grid, effects, quantities, score

TITLE = "Environment response — generated effects of φ against the simulator's"
LABELS: dict[str, str] = {"apex_m": "apex (m)", "flight_s": "flight time (s)", "step_length_m": "step length (m)",
                          "drift_along_wind_m": "drift along the wind (m)", "drift_x_m": "drift x (m)",
                          "drift_z_m": "drift z (m)"}


def grid(runner: Runner) -> list[list[float]]:
    """Earth first, then the fig5 conditions (sweeps, combinations and their parts), duplicates merged."""
    envs = [list(EARTH)] + [env for _, env in conditions(runner) if tuple(env) != tuple(EARTH)]
    check_grid(envs)
    return envs


def env_aware(runner: Runner, spec: ModelSpec) -> bool:
    """Whether φ reaches the method (continuous adapters or PhysDiff's projection)."""
    return runner.sim_mode(spec) == "continuous" or spec.physdiff is not None


def measure(runner: Runner, spec: ModelSpec) -> dict[str, Any]:
    """Generate under every φ, re-track the Earth motions under every φ, score the responses."""
    import time

    from simdiff.motion.rigid import batch_joints_from_features
    from simdiff.sim.env import Environment

    c, o = runner.config, runner.config.env_control
    envs = grid(runner)
    captions = [p for p in o.prompts for _ in range(o.seeds)]
    units = [(p, s) for p in o.prompts for s in range(o.seeds)]
    alpha = runner.alpha(spec) if runner.is_simdiff(spec) else None
    generated: dict[tuple[float, ...], np.ndarray] = {}
    seconds = 0.0
    for env in envs if env_aware(runner, spec) else [list(EARTH)]:
        fn = runner.generate_fn(spec, "ddim", alpha, env)
        feats, s = runner.generate(fn, captions, [o.length] * len(captions), c.seed)
        seconds += s
        generated[tuple(env)] = batch_joints_from_features(feats, [o.length] * len(captions), fn.foot_lock)
    earth = generated[tuple(EARTH)]
    start = time.perf_counter()
    jobs = [(i, env) for env in envs for i in range(len(units))]
    results = list(runner.sim([earth[i] for i, _ in jobs], [Environment(*env) for _, env in jobs]))
    sim_s = time.perf_counter() - start
    sims: dict[tuple[int, tuple[float, ...]], dict[str, float] | None] = {}
    statuses: dict[str, int] = {}
    errors: list[str] = []
    for (i, env), (rollout, info) in zip(jobs, results):
        ok = not isinstance(info, str) and bool(_get(info, "success")) and rollout is not None and len(rollout) >= 2
        status = "error" if isinstance(info, str) else str(_get(info, "status", "?"))
        statuses[status] = statuses.get(status, 0) + 1
        if isinstance(info, str) and len(errors) < 3:
            errors.append(info)
        sims[(i, tuple(env))] = quantities(np.asarray(rollout), env) if ok else None
    records = []
    for env in envs:
        motions = generated.get(tuple(env), earth)
        for i, unit in enumerate(units):
            records.append({"unit": f"{unit[0]}#{unit[1]}", "env": env, "gen": quantities(motions[i], env),
                            "sim": sims[(i, tuple(env))]})
    effs = effects(records)
    return {"records": records, "scores": score(effs, resamples=o.resamples, seed=c.seed),
            "additivity": additivity(effs, resamples=o.resamples, seed=c.seed), "effects": effs,
            "rollouts": statuses, "rollout_errors": errors, "env_aware": env_aware(runner, spec), "gen_s": seconds, "sim_s": sim_s,
            "units": len(units), "envs": envs}


def _reading_summary(reads: list[dict[str, float] | None], gravity: float) -> dict[str, Any]:
    """``{gravity, n, read, median, q25, q75, within_10pct, worst_fit_mm}`` of readings (None: no flight)."""
    got = [r for r in reads if r is not None]
    g = np.array([r["gravity"] for r in got])
    out: dict[str, Any] = {"gravity": gravity, "n": len(reads), "read": len(got)}
    if got:
        out.update(median=float(np.median(g)), q25=float(np.percentile(g, 25)), q75=float(np.percentile(g, 75)),
                   within_10pct=float(np.mean(np.abs(g - gravity) <= 0.1 * abs(gravity))),
                   worst_fit_mm=float(max(1000 * r["rmse_m"] for r in got)))
    return out


def measure_readout(runner: Runner) -> dict[str, Any]:
    """The gravity readout on the split's real jumps (Earth) and on the simulator's rollouts of them under each
    gravity of the grid (rollouts that fell are left out)."""
    from simdiff.eval.experiments.clips import split_clips
    from simdiff.motion.gravity_readout import read_gravity
    from simdiff.sim.env import Environment

    clips = split_clips(runner, "jump", runner.config.env_control.readout_clips, flight=True)
    gravities = sorted({float(e[0]) for e in grid(runner) if e[1] == 0 and e[2] == 0})
    jobs = [(i, g) for g in gravities for i in range(len(clips))]
    results = runner.sim([clips[i]["joints"] for i, _ in jobs], [Environment(g, 0.0, 0.0) for _, g in jobs])
    reads: dict[float, list[dict[str, float] | None]] = {g: [] for g in gravities}
    fell: dict[float, int] = {g: 0 for g in gravities}
    for (_, g), (rollout, info) in zip(jobs, results):
        if isinstance(info, str) or not _get(info, "success") or rollout is None or len(rollout) < 2:
            fell[g] += 1
            continue
        reads[g].append(read_gravity(np.asarray(rollout)))
    return {"clips": [c["id"] for c in clips], "real": _reading_summary([read_gravity(c["joints"]) for c in clips],
                                                                          EARTH[0]),
            "simulated": [{**_reading_summary(reads[g], g), "fell": fell[g]} for g in gravities]}


def _get(info: Any, key: str, default: Any = None) -> Any:
    return info.get(key, default) if isinstance(info, dict) else getattr(info, key, default)


def plan(runner: Runner) -> list[RowPlan]:
    c, o = runner.config, runner.config.env_control
    if not o.prompts or o.seeds < 1:
        raise SimdiffError("env_response needs 'env_control.prompts' and 'env_control.seeds' >= 1")
    envs = grid(runner)
    n = len(o.prompts) * o.seeds
    plans = []
    for spec in c.models:
        mode = runner.sim_mode(spec)
        if mode == "categorical" and spec.env_index is None:
            raise SimdiffError(f"env_response: {spec.name!r} has categorical adapters; give its 'env_index'")
        alpha = runner.alpha(spec) if mode else None
        inputs = {"row": "env_response", **runner.method_inputs(spec, "ddim", alpha), "seed": c.seed, "envs": envs,
                  "prompts": o.prompts, "seeds": o.seeds, "length": o.length, "resamples": o.resamples,
                  "projector": {"residual_bound": c.projector.residual_bound}}
        gens = len(envs) if env_aware(runner, spec) else 1
        est = runner.motion_seconds(spec, "ddim", n * gens, o.length / FPS) + n * len(envs) * runner.projection_seconds(o.length / FPS)
        plans.append(RowPlan(safe(spec.name), {"method": spec.name, "alpha": alpha}, inputs, est,
                             lambda r, spec=spec: measure(r, spec)))
    if o.readout_clips > 0:
        inputs = {"row": "env_readout", "clips": o.readout_clips, "envs": envs, **runner.data_inputs(),
                  "projector": {"residual_bound": c.projector.residual_bound}}
        plans.append(RowPlan("readout", {"method": "readout check", "part": "readout"}, inputs,
                             o.readout_clips * sum(e[1] == e[2] == 0 for e in envs) * runner.projection_seconds(),
                             lambda r: measure_readout(r)))
    return plans


def _interval(v: list[float] | None, digits: int = 2) -> str:
    if v is None or v[0] is None or v[0] != v[0]:
        return "—"
    est, lo, hi = v
    if lo != lo:
        return f"{est:.{digits}f}"
    return f"{est:.{digits}f} [{lo:.{digits}f}, {hi:.{digits}f}]"


def figure(rows: list[dict[str, Any]], path: Any) -> Any:
    """Generated effect against simulated effect, one panel per quantity, one colour per method; y = x is physics."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    panels = [("gravity", "apex_m"), ("gravity", "flight_s"), ("gravity", "step_length_m"), ("wind", "drift_along_wind_m")]
    fig, axes = plt.subplots(1, len(panels), figsize=(3.4 * len(panels), 3.3))
    for ax, (f, q) in zip(axes, panels):
        lim = 0.0
        for r in rows:
            pts = [(e["dsim"][q], e["dgen"][q]) for e in r["effects"] if e["dsim"] is not None and
                   (e["factor"] == f or (f == "gravity" and e["factor"] == "combo" and q != "drift_along_wind_m"))]
            if pts:
                xs, ys = np.asarray(pts).T
                ax.scatter(xs, ys, s=14, alpha=0.7, label=r["method"])
                lim = max(lim, float(np.abs(xs).max()), float(np.abs(ys).max()))
        lim = lim * 1.1 or 1.0
        ax.plot([-lim, lim], [-lim, lim], color="#777777", lw=1, ls="--")
        ax.axhline(0, color="black", lw=0.5)
        ax.axvline(0, color="black", lw=0.5)
        ax.set_xlim(-lim, lim)
        ax.set_ylim(-lim, lim)
        ax.set_xlabel(f"simulated Δ {LABELS[q]}")
        ax.set_ylabel(f"generated Δ {LABELS[q]}")
        ax.set_title(f"{f}: {LABELS[q]}", fontsize=9)
    axes[0].legend(fontsize=7)
    return save_figure(fig, path)


def finish(runner: Runner, report: dict[str, Any]) -> list[str]:
    c, o = runner.config, runner.config.env_control
    checks = [r for r in report["rows"] if r.get("part") == "readout"]
    rows = [r for r in report["rows"] if r.get("part") != "readout"]
    for r in rows:  # scored again from the stored effects: a scoring change needs no new rollouts
        r["scores"] = score(r["effects"], resamples=o.resamples, seed=c.seed)
        r["additivity"] = additivity(r["effects"], resamples=o.resamples, seed=c.seed)
    envs = grid(runner)
    path = figure(rows, runner.out / "env_response.png")
    lines = [f"Prompts: {', '.join('“' + p + '”' for p in o.prompts)}; {o.seeds} seeds each (units n = "
             f"{len(o.prompts) * o.seeds}); {o.length} frames; DDIM; seed {c.seed} (the same noise for every φ); "
             "α per method: " + ", ".join(f"{r['method']} {r['alpha']:g}" for r in rows if r.get("alpha") is not None)
             + f"; tracker residual bound {c.projector.residual_bound}.",
             f"Grid ({len(envs)} φ): " + ", ".join(fmt_env(e) for e in envs) + ".", "",
             "Effect = quantity under φ − the same prompt and seed under Earth. Simulated effect: the method's own Earth "
             "motion re-tracked under φ minus it re-tracked under Earth (flights follow gravity); pairs whose rollouts "
             "fell are left out. Sign agreement counts pairs with a physical effect above the tolerance; slope ratio = "
             "Σ Δgen·Δsim / Σ Δsim² (1: the physical size, 0: no response). [95 % bootstrap interval over prompt × seed "
             f"units, {o.resamples} resamples.]", "",
             "| Method | factor | quantity | units / pairs / with effect | mean Δ generated | mean Δ simulated | "
             "sign agreement | slope ratio |", "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        for s in r["scores"]:
            lines.append(f"| {r['method']} | {s['factor']} | {LABELS[s['quantity']]} | {s['n_units']} / {s['n_pairs']} / "
                         f"{s['n_effect']} | {s['mean_dgen']:+.3f} | {s['mean_dsim']:+.3f} | "
                         f"{_interval(s['sign_agreement'])} | {_interval(s['slope_ratio'])} |")
    if any(r["additivity"] for r in rows):
        lines += ["", "Additivity error of combinations: mean |Δ(φ) − Σ Δ(single-factor parts)| over units "
                      "(generated; simulated for reference: the simulator's own non-additivity).", "",
                  "| Method | φ | quantity | generated | simulated | units (gen / sim) |", "|---|---|---|---|---|---|"]
        for r in rows:
            for a in r["additivity"]:
                lines.append(f"| {r['method']} | {fmt_env(a['env'])} | {LABELS[a['quantity']]} | "
                             f"{_interval(a['generated'], 3)} | {_interval(a['simulated'], 3)} | "
                             f"{a['n_generated']} / {a['n_simulated']} |")
    silent = [r["method"] for r in rows if not r["scores"]]
    if silent:
        lines += ["", f"No scored pair for {', '.join(silent)}: every rollout of its Earth motions or of φ fell "
                      "(see the rollouts below)."]
    lines += ["", "| Method | φ reaches it | rollouts (status: count) | generation s | simulation s |", "|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['method']} | {'yes' if r['env_aware'] else 'no (one generation for every φ)'} | "
                     + ", ".join(f"{k}: {v}" for k, v in sorted(r["rollouts"].items())) + f" | {r['gen_s']:.1f} | {r['sim_s']:.1f} |")
    for r in rows:
        for e in r.get("rollout_errors") or []:
            lines.append(f"* {r['method']} rollout error: {e}")
    for r in checks:
        lines += ["", f"Readout check (the measure's own error): {len(r['clips'])} of the split's real jumps with a "
                  "readable flight, read as they are and re-tracked by the simulator under each gravity (flights "
                  "follow gravity); g read is the centre of mass's parabola over the flights "
                  "(`simdiff.motion.gravity_readout`).", "",
                  "| motions | requested g | read / n | median g read [IQR] | within 10 % | worst fit (mm) |",
                  "|---|---|---|---|---|---|"]
        for name, s in [("real", r["real"])] + [("simulated", s) for s in r["simulated"]]:
            body = (f"{s['median']:.2f} [{s['q25']:.2f}, {s['q75']:.2f}] | {s['within_10pct']:.0%} | "
                    f"{s['worst_fit_mm']:.0f}") if s["read"] else "— | — | —"
            fell = f" ({s['fell']} fell)" if s.get("fell") else ""
            lines.append(f"| {name} | {s['gravity']:g} | {s['read']} / {s['n']}{fell} | {body} |")
    lines += ["", f"![generated vs simulated effects]({path.name})"]
    return lines
