"""Closed loop: re-track each generated motion under its own φ in the simulator.

For each φ in ``envs`` and each method, ``retrack_samples`` test captions (with their test
lengths, drawn as the protocol draws them) are generated under φ (MDM ignores φ; PhysDiff
projects under φ; SimDiff is conditioned on φ), then replayed by the tracking controller
under φ (:func:`simdiff.sim.project`). Reported: the tracked fraction (no fall, no
instability to the last frame), d_L2 (paper eq. 13: mean per-frame distance between the
motion and its rollout in the normalised 263-d space; over the frames tracked) and the mean
joint position error. ``include_ground_truth`` adds the test motions themselves.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from simdiff.eval.experiments.config import ModelSpec
from simdiff.eval.experiments.report import fmt_env, save_figure, value
from simdiff.eval.experiments.runner import EARTH, RowPlan, Runner, env_key, safe

TITLE = "Closed loop — re-tracking generated motions under their φ"


def _get(info: Any, key: str, default: Any = float("nan")) -> Any:
    if isinstance(info, dict):
        return info.get(key, default)
    return getattr(info, key, default)


def measure(runner: Runner, spec: ModelSpec | None, env: list[float]) -> dict[str, Any]:
    """Generate (or take the test motions), replay under φ, summarise."""
    import torch

    from simdiff.motion.features import extend_last_frame, features_to_joints
    from simdiff.sim.env import Environment

    n = runner.config.retrack_samples
    items = runner.test_motions(n)
    if spec is None:
        feats = [np.asarray(f, dtype=np.float64) for f in items["features"]]
        seconds = 0.0
    else:
        alpha = runner.alpha(spec) if runner.is_simdiff(spec) else None
        out, seconds = runner.generate(runner.generate_fn(spec, "ddim", alpha, env), items["captions"], items["lengths"],
                                       runner.config.seed * 7 + 1)
        out = out.to(torch.float64).cpu().numpy()
        feats = [out[i, :L] for i, L in enumerate(items["lengths"])]
    motions = [extend_last_frame(np.asarray(features_to_joints(f)), f) for f in feats]
    phi = Environment(*env)
    results = list(runner.sim(motions, [phi] * len(motions)))
    samples = []
    for (rollout, info), cap in zip(results, items["captions"]):
        if isinstance(info, str):
            samples.append({"caption": cap, "tracked": False, "status": "error", "error": info, "d_l2": None, "err_mm": None})
            continue
        d = _get(info, "d_l2")
        e = _get(info, "err_mm")
        samples.append({"caption": cap, "tracked": bool(_get(info, "success", False)), "status": _get(info, "status", "?"),
                        "d_l2": None if d is None or d != d else float(d), "err_mm": None if e is None or e != e else float(e)})
    d_l2 = [s["d_l2"] for s in samples if s["d_l2"] is not None]
    err = [s["err_mm"] for s in samples if s["err_mm"] is not None]
    return {"samples": samples, "n": len(samples), "tracked": sum(s["tracked"] for s in samples),
            "tracked_fraction": float(np.mean([s["tracked"] for s in samples])),
            "d_l2_mean": float(np.mean(d_l2)) if d_l2 else None, "d_l2_median": float(np.median(d_l2)) if d_l2 else None,
            "err_mm_mean": float(np.mean(err)) if err else None, "errors": sum(s["status"] == "error" for s in samples),
            "gen_s_per_motion": seconds / max(1, len(samples))}


def plan(runner: Runner) -> list[RowPlan]:
    c = runner.config
    envs = c.envs or [list(EARTH)]
    n = c.retrack_samples
    data = {**runner.data_inputs(), "samples": n, "projector": dataclasses.asdict(c.projector)}
    plans = []
    for env in envs:
        env = [float(v) for v in env]
        track_s = n * runner.projection_seconds()
        if c.include_ground_truth:
            plans.append(RowPlan(safe(f"ground_truth_{env_key(env)}"), {"method": "Ground truth", "env": env},
                                 {"row": "retrack_gt", "env": env, **data}, track_s,
                                 lambda r, env=env: measure(r, None, env)))
        for spec in c.models:
            alpha = runner.alpha(spec) if runner.is_simdiff(spec) else None
            inputs = {"row": "retrack", **data, **runner.method_inputs(spec, "ddim", alpha, env)}
            plans.append(RowPlan(safe(f"{spec.name}_{env_key(env)}"), {"method": spec.name, "env": env, "alpha": alpha},
                                 inputs, runner.motion_seconds(spec, "ddim", n) + track_s,
                                 lambda r, spec=spec, env=env: measure(r, spec, env)))
    return plans


def figure(rows: list[dict[str, Any]], path: Any) -> Any:
    """Tracked fraction and d_L2 per φ, one bar per method."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    envs = list(dict.fromkeys(tuple(r["env"]) for r in rows))
    methods = list(dict.fromkeys(r["method"] for r in rows))
    width = 0.8 / len(methods)
    fig, axes = plt.subplots(1, 2, figsize=(max(7.0, 2.2 * len(envs) * 2), 3.3))
    for j, method in enumerate(methods):
        xs, frac, dl2 = [], [], []
        for i, env in enumerate(envs):
            r = next((r for r in rows if r["method"] == method and tuple(r["env"]) == env), None)
            if r is not None:
                xs.append(i + (j - (len(methods) - 1) / 2) * width)
                frac.append(r["tracked_fraction"])
                dl2.append(r["d_l2_mean"] or 0.0)
        axes[0].bar(xs, frac, width * 0.95, label=method)
        axes[1].bar(xs, dl2, width * 0.95, label=method)
    for ax, title in zip(axes, ("tracked fraction ↑", "d_L2 (normalised features) ↓")):
        ax.set_xticks(range(len(envs)), [fmt_env(e) for e in envs], fontsize=8)
        ax.set_xlabel("φ = (g_z, w_x, w_y)")
        ax.set_title(title, fontsize=10)
    axes[0].set_ylim(0, 1.05)
    axes[0].legend(fontsize=8)
    return save_figure(fig, path)


def finish(runner: Runner, report: dict[str, Any]) -> list[str]:
    c = runner.config
    rows = report["rows"]
    path = figure(rows, runner.out / "retrack.png")
    lines = [f"{c.retrack_samples} test captions per (method, φ), DDIM; tracker residual bound {c.projector.residual_bound} "
             "(fraction of m·|g_z|).", "",
             "| Method | φ (g, w_x, w_y) | tracked | d_L2 mean (median) ↓ | joint error (mm) ↓ | errors |",
             "|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['method']} | {fmt_env(r['env'])} | {r['tracked']}/{r['n']} ({r['tracked_fraction']:.0%}) | "
                     f"{value(r['d_l2_mean'], 2)} ({value(r['d_l2_median'], 2)}) | {value(r['err_mm_mean'], 1)} | {r['errors']} |")
    lines += ["", f"![closed loop]({path.name})"]
    return lines
