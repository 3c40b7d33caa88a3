"""Figure 5: environment control — jump apex vs gravity, drift vs wind, an unseen combination.

For each φ (the gravity sweep at zero wind, the w_x and w_y sweeps at Earth gravity, each
combination and its single-factor parts) SimDiff generates every prompt × seed (the same
noise for every φ) and we measure per motion

* apex height (m): peak root height above standing height (the median root height of the
  first 5 frames, 0.25 s);
* drift along HumanML3D x and z (m): root displacement from the first to the last frame
  (w_x pushes along +x, w_y along +z, the facing direction at frame 0);
* gravity read from the flights (m/s²): the centre of mass's parabola over the airborne frames
  (:func:`simdiff.motion.gravity_readout.read_gravity`), over the motions with a readable flight.

MDM (env-blind) gives one set of motions: the flat reference line. Filmstrips show the
first prompt at the first seed under selected φ.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from simdiff.errors import SimdiffError
from simdiff.eval.experiments.config import ModelSpec
from simdiff.eval.experiments.report import fmt_env, save_figure
from simdiff.eval.experiments.runner import EARTH, RowPlan, Runner, env_key, safe
from simdiff.eval.stats import t_interval
from simdiff.fsio import save_npy

TITLE = "Figure 5 — environment control"
STANDING_FRAMES: int = 5


def motion_stats(joints: np.ndarray) -> dict[str, float | None]:
    """(T, 22, 3) joints → apex height (m), drift x / z (m), airborne fraction (lowest joint > 5 cm), gravity read
    from the flights (m/s², None without a readable flight) and that fit's error (mm)."""
    from simdiff.motion.gravity_readout import read_gravity

    root = joints[:, 0]
    standing = float(np.median(root[:STANDING_FRAMES, 1]))
    reading = read_gravity(joints)
    return {"apex_m": float(root[:, 1].max() - standing), "drift_x_m": float(root[-1, 0] - root[0, 0]),
            "drift_z_m": float(root[-1, 2] - root[0, 2]),
            "airborne": float((joints[:, :, 1].min(axis=1) > 0.05).mean()),
            "gravity_read": None if reading is None else reading["gravity"],
            "flight_fit_mm": None if reading is None else 1e3 * reading["rmse_m"]}


def conditions(runner: Runner) -> list[tuple[str, list[float]]]:
    """(factor, φ) in plot order, duplicates merged (the first factor wins)."""
    o = runner.config.env_control
    g0 = EARTH[0]
    out: dict[tuple[float, ...], str] = {}
    for g in o.gravity:
        out.setdefault((float(g), 0.0, 0.0), "gravity")
    for w in o.wind:
        out.setdefault((g0, float(w), 0.0), "wind_x")
    for w in o.wind:
        out.setdefault((g0, 0.0, float(w)), "wind_y")
    for g, wx, wy in o.combos:
        out.setdefault((float(g), 0.0, 0.0), "gravity")
        out.setdefault((g0, float(wx), 0.0), "wind_x")
        out.setdefault((g0, 0.0, float(wy)), "wind_y")
        out[(float(g), float(wx), float(wy))] = "combo"
    return [(factor, list(env)) for env, factor in out.items()]


def measure(runner: Runner, spec: ModelSpec, env: list[float] | None, key: str) -> dict[str, Any]:
    """Generate every prompt × seed under φ; per-motion statistics (of the written joints) and their mean ± 95% CI."""
    from simdiff.motion.rigid import batch_joints_from_features

    o = runner.config.env_control
    captions = [p for p in o.prompts for _ in range(o.seeds)]
    fn = runner.generate_fn(spec, "ddim", (o.alpha if o.alpha is not None else runner.alpha(spec))
                           if runner.is_simdiff(spec) else None, env)
    feats, seconds = runner.generate(fn, captions, [o.length] * len(captions), runner.config.seed)
    joints = batch_joints_from_features(feats, [o.length] * len(captions), fn.foot_lock)
    samples = [{"prompt": c, "seed": i % o.seeds, **motion_stats(j)} for i, (c, j) in enumerate(zip(captions, joints))]
    save_npy(runner.rows_dir / f"{key}.motion.npy", joints[0])
    summary = {}
    for k in ("apex_m", "drift_x_m", "drift_z_m", "airborne"):
        v = np.array([s[k] for s in samples])
        mean, half = t_interval(v)
        summary[k] = {"mean": mean, "ci95": half if half == half else 0.0, "std": float(v.std(ddof=1)) if len(v) > 1 else 0.0}
    for k in ("gravity_read", "flight_fit_mm"):  # over the motions whose flights could be read
        v = np.array([s[k] for s in samples if s[k] is not None])
        mean, half = t_interval(v) if len(v) else (float("nan"), float("nan"))
        summary[k] = {"mean": mean, "ci95": half if half == half else 0.0, "n": int(len(v))}
    return {"summary": summary, "samples": samples, "s_per_motion": seconds / len(captions)}


def plan(runner: Runner) -> list[RowPlan]:
    c = runner.config
    o = c.env_control
    if not o.prompts or o.seeds < 1:
        raise SimdiffError("fig5 needs 'env_control.prompts' and 'env_control.seeds' >= 1")
    n = len(o.prompts) * o.seeds
    runner.rows_dir.mkdir(parents=True, exist_ok=True)
    plans = []
    for spec in c.models:
        mode = runner.sim_mode(spec)
        if mode == "categorical":
            raise SimdiffError(f"fig5 needs continuous adapters (φ); {spec.name!r} is categorical")
        envs = conditions(runner) if mode == "continuous" else [("reference", None)]
        alpha = (o.alpha if o.alpha is not None else runner.alpha(spec)) if mode else None
        for factor, env in envs:
            key = safe(f"{spec.name}_{env_key(env)}" if env is not None else spec.name)
            inputs = {"row": "env_control", **runner.method_inputs(spec, "ddim", alpha, env), "seed": c.seed,
                      "prompts": o.prompts, "seeds": o.seeds, "length": o.length}
            plans.append(RowPlan(key, {"method": spec.name, "factor": factor, "env": env, "alpha": alpha}, inputs,
                                 runner.motion_seconds(spec, "ddim", n),
                                 lambda r, spec=spec, env=env, key=key: measure(r, spec, env, key)))
    return plans


def _ref(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    return [r for r in rows if r["factor"] == "reference"]


def sweep_figure(rows: list[dict[str, Any]], path: Path) -> Path:
    """Apex vs g_z, drift x vs w_x, drift z vs w_y (mean ± 95% CI); env-blind models as flat lines."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    panels = [("gravity", 0, "apex_m", "g_z (m/s²)", "apex height (m)"),
              ("wind_x", 1, "drift_x_m", "w_x (N)", "drift along x (m)"),
              ("wind_y", 2, "drift_z_m", "w_y (N)", "drift along z (m)")]
    fig, axes = plt.subplots(1, 3, figsize=(11, 3.3))
    for ax, (factor, idx, key, xlabel, ylabel) in zip(axes, panels):
        for method in dict.fromkeys(r["method"] for r in rows if r["factor"] != "reference"):
            mine = [r for r in rows if r["method"] == method and (r["factor"] == factor or _on_axis(r, factor))]
            mine.sort(key=lambda r: r["env"][idx])
            ax.errorbar([r["env"][idx] for r in mine], [r["summary"][key]["mean"] for r in mine],
                        yerr=[r["summary"][key]["ci95"] for r in mine], fmt="o-", capsize=3, label=method)
        for r in _ref(rows):
            m, e = r["summary"][key]["mean"], r["summary"][key]["ci95"]
            line = ax.axhline(m, color="#777777", ls="--", lw=1, label=f"{r['method']} (env-blind)")
            ax.axhspan(m - e, m + e, color=line.get_color(), alpha=0.12)
        ax.set_xlabel(xlabel)
        ax.set_ylabel(ylabel)
    axes[0].legend(fontsize=8)
    return save_figure(fig, path)


def _on_axis(row: dict[str, Any], factor: str) -> bool:
    """Earth (−9.81, 0, 0) belongs to every sweep."""
    return row["env"] == list(EARTH)


def combination_parts(rows: list[dict[str, Any]], combo: dict[str, Any]) -> dict[str, dict[str, Any] | None]:
    """The single-factor rows a combination φ = (g, w_x, w_y) is compared with."""
    g, wx, wy = combo["env"]
    find = lambda env: next((r for r in rows if r["method"] == combo["method"] and r["env"] == env), None)  # noqa: E731
    return {"gravity": find([g, 0.0, 0.0]), "wind_x": find([EARTH[0], wx, 0.0]), "wind_y": find([EARTH[0], 0.0, wy]),
            "earth": find(list(EARTH))}


def combination_figure(rows: list[dict[str, Any]], path: Path) -> Path:
    """Grouped bars: apex, drift x, drift z for each combination, its parts, Earth and MDM."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    combos = [r for r in rows if r["factor"] == "combo"]
    keys = [("apex_m", "apex (m)"), ("drift_x_m", "drift x (m)"), ("drift_z_m", "drift z (m)")]
    fig, axes = plt.subplots(len(combos), 1, figsize=(8, 3.0 * len(combos)), squeeze=False)
    for ax, combo in zip(axes[:, 0], combos):
        parts = combination_parts(rows, combo)
        bars = [(f"{combo['method']} φ={fmt_env(combo['env'])} (unseen)", combo)]
        bars += [(f"{name} only φ={fmt_env(r['env'])}", r) for name, r in parts.items() if r is not None and name != "earth"]
        if parts["earth"] is not None:
            bars.append((f"Earth φ={fmt_env(parts['earth']['env'])}", parts["earth"]))
        bars += [(f"{r['method']} (env-blind)", r) for r in _ref(rows)]
        width = 0.8 / len(bars)
        for j, (label, r) in enumerate(bars):
            xs = np.arange(len(keys)) + (j - (len(bars) - 1) / 2) * width
            ax.bar(xs, [r["summary"][k]["mean"] for k, _ in keys], width * 0.95,
                   yerr=[r["summary"][k]["ci95"] for k, _ in keys], capsize=2, label=label)
        ax.axhline(0, color="black", lw=0.6)
        ax.set_xticks(range(len(keys)), [t for _, t in keys])
        ax.legend(fontsize=7, ncol=2)
    return save_figure(fig, path)


def filmstrips(runner: Runner, rows: list[dict[str, Any]]) -> list[Path]:
    """Filmstrips of the first prompt/seed: gravity sweep, wind extremes, each combination with its parts."""
    from simdiff.viz.stick import render_filmstrip

    o = runner.config.env_control
    if o.filmstrip_frames < 1 or not rows:
        return []

    def load(r: dict[str, Any]) -> np.ndarray | None:
        f = runner.rows_dir / f"{r['key']}.motion.npy"
        return np.load(f) if f.is_file() else None

    def label(r: dict[str, Any]) -> str:
        env = "env-blind" if r["env"] is None else f"g = {r['env'][0]:g} m/s², w = ({r['env'][1]:g}, {r['env'][2]:g}) N"
        return f"{r['method']}, {env}: “{o.prompts[0]}”"

    refs = _ref(rows)
    groups: dict[str, list[dict[str, Any]]] = {
        "gravity": [r for r in rows if r["factor"] == "gravity"] + refs,
        "wind": [r for r in rows if r["factor"] in ("wind_x", "wind_y") and abs(max(r["env"][1:], key=abs)) ==
                 max(abs(w) for w in o.wind)] + [r for r in rows if r["env"] == list(EARTH)],
    }
    for i, combo in enumerate(r for r in rows if r["factor"] == "combo"):
        groups[f"combo{i}"] = [combo] + [p for p in combination_parts(rows, combo).values() if p is not None] + refs
    paths = []
    for name, members in groups.items():
        members = [m for m in dict((id(m), m) for m in members).values() if load(m) is not None]
        if members:
            path = runner.out / f"fig5_strip_{name}.png"
            render_filmstrip([load(m) for m in members], path, [label(m) for m in members], n_frames=o.filmstrip_frames)
            paths.append(path)
    return paths


def finish(runner: Runner, report: dict[str, Any]) -> list[str]:
    o = runner.config.env_control
    rows = report["rows"]
    sweep = sweep_figure(rows, runner.out / "fig5.png")
    combos = [r for r in rows if r["factor"] == "combo"]
    combo_fig = combination_figure(rows, runner.out / "fig5_combination.png") if combos else None
    strips = filmstrips(runner, rows)
    cell = lambda r, k: f"{r['summary'][k]['mean']:+.3f} ± {r['summary'][k]['ci95']:.3f}"  # noqa: E731
    alpha_text = "the model's" if o.alpha is None else f"{o.alpha:g}"
    lines = [f"Prompts: {', '.join('“' + p + '”' for p in o.prompts)}; {o.seeds} seeds each (same noise for every φ); "
             f"{o.length} frames; DDIM; SimDiff α = {alpha_text}. Apex: peak root height above the median root height of "
             f"the first {STANDING_FRAMES} frames; drift: root displacement first → last frame (m); g read: the gravity "
             "of the centre of mass's parabola over the flights (m/s², mean ± 95% CI over the motions with a flight of "
             "≥ 5 airborne frames, their count in brackets) and that fit's error (mm).", "",
             "| Method | factor | φ (g, w_x, w_y) | apex (m) | drift x (m) | drift z (m) | airborne | g read (m/s²) "
             "| fit error (mm) |", "|---|---|---|---|---|---|---|---|---|"]
    n = o.seeds * len(o.prompts)
    for r in rows:
        g = r["summary"].get("gravity_read", {"n": 0})
        fit = r["summary"].get("flight_fit_mm", {"n": 0})
        read = f"{g['mean']:+.2f} ± {g['ci95']:.2f} [{g['n']}/{n}]" if g["n"] else f"— [0/{n}]"
        lines.append(f"| {r['method']} | {r['factor']} | {fmt_env(r['env'])} | {cell(r, 'apex_m')} | {cell(r, 'drift_x_m')} | "
                     f"{cell(r, 'drift_z_m')} | {r['summary']['airborne']['mean']:.2f} | {read} | "
                     f"{format(fit['mean'], '.0f') if fit['n'] else '—'} |")
    for combo in combos:
        parts = combination_parts(rows, combo)
        lines += ["", f"Unseen combination φ = {fmt_env(combo['env'])} vs its single-factor parts:", "",
                  "| quantity | combination | single factor | φ of the single factor |", "|---|---|---|---|"]
        for key, part in (("apex_m", "gravity"), ("drift_x_m", "wind_x"), ("drift_z_m", "wind_y")):
            p = parts[part]
            lines.append(f"| {key} | {cell(combo, key)} | {cell(p, key) if p else '—'} | {fmt_env(p['env']) if p else '—'} |")
    lines += ["", f"![sweeps]({sweep.name})"]
    if combo_fig:
        lines.append(f"![combination]({combo_fig.name})")
    lines += [f"![filmstrip]({p.name})" for p in strips]
    return lines
