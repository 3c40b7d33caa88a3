"""Figure 4: inference time per motion at batch 1 — each method × DDPM/DDIM, ratios to MDM-DDIM.

Each cell generates one motion of ``timing.length`` frames from ``timing.text``, ``repeats``
times (DDPM: ``ddpm_repeats``) after ``warmup`` untimed DDIM runs, and reports the median
wall time, text encoding included. PhysDiff's time includes its four simulator projections
(an in-process simulator at batch 1), a ``simulate`` method's its one re-tracking of the final
sample (``simdiff generate --simulate``); the simulator share is reported separately.
"""

from __future__ import annotations

import platform
import statistics
import time
from dataclasses import asdict
from typing import Any

import numpy as np

from simdiff.eval.experiments.config import ModelSpec
from simdiff.eval.experiments.report import save_figure, speed_comparison, value
from simdiff.eval.experiments.rows import method_key
from simdiff.eval.experiments.runner import EARTH, FPS, RowPlan, Runner

TITLE = "Figure 4 — inference time per motion (batch 1)"


def measure(runner: Runner, spec: ModelSpec, sampler: str) -> dict[str, Any]:
    """Median seconds of ``repeats`` batch-1 generations (and of their projections)."""
    from simdiff.baselines.physdiff import physdiff_generate

    t = runner.config.timing
    gen = runner.model(spec)
    kwargs: dict[str, Any] = {}
    if gen.is_simdiff:
        kwargs = {"env_index": spec.env_index}
        if gen.config.sim.mode == "continuous":
            kwargs["env"] = spec.env or list(EARTH)
    for w in range(t.warmup):
        gen.generate([t.text], t.length, runner.sampling(spec, "ddim"), seed=w, **kwargs)
    repeats = t.ddpm_repeats if sampler == "ddpm" else t.repeats
    times, proj = [], []
    for r in range(repeats):
        start = time.perf_counter()
        if spec.physdiff is not None:
            _, hook = physdiff_generate(gen, [t.text], [t.length], runner.physdiff_config(spec, sampler),
                                        projector=runner.serial_projector(), seed=r,
                                        sampling=runner.sampling(spec, sampler), **kwargs)
            proj.append(sum(e["wall_s"] for e in hook.log))
        else:
            out = gen.generate([t.text], t.length, runner.sampling(spec, sampler), seed=r, **kwargs)
            if spec.simulate:  # the simulated finish of `simdiff generate --simulate`: one in-process re-tracking
                from simdiff.motion.features import features_to_joints
                from simdiff.sim.env import Environment

                begin = time.perf_counter()
                joints = np.asarray(features_to_joints(out.clips()[0].detach().cpu().double()))
                env = Environment(*kwargs["env"]) if kwargs.get("env") else Environment()
                list(runner.serial_projector(anchor_stance=True)([joints], [env]))
                proj.append(time.perf_counter() - begin)
        times.append(time.perf_counter() - start)
    return {"times_s": times, "median_s": statistics.median(times),
            "projection_median_s": statistics.median(proj) if proj else None, "repeats": repeats}


def plan(runner: Runner) -> list[RowPlan]:
    c = runner.config
    t = c.timing
    machine = {"host": platform.node(), "threads": runner.provenance["machine"]["torch_threads"]}
    plans = []
    for spec in c.models:
        for sampler in spec.own_samplers(c.samplers):
            repeats = t.ddpm_repeats if sampler == "ddpm" else t.repeats
            est = runner.motion_seconds(spec, sampler, repeats, t.length / FPS, workers=1)
            est += runner.motion_seconds(spec, "ddim", t.warmup, t.length / FPS, workers=1)
            inputs = {"row": "timing", **runner.method_inputs(spec, sampler, runner.alpha(spec) if runner.is_simdiff(spec) else None), "timing": asdict(t),
                      "machine": machine}
            plans.append(RowPlan(method_key(spec, sampler, None), {"method": spec.name, "sampler": sampler}, inputs, est,
                                 lambda r, spec=spec, sampler=sampler: measure(r, spec, sampler)))
    return plans


def figure(rows: list[dict[str, Any]], ref: float, path: Any) -> Any:
    """Bars of median s/motion (log scale), projection share hatched, ratio to the reference on each bar."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    methods = list(dict.fromkeys(r["method"] for r in rows))
    samplers = list(dict.fromkeys(r["sampler"] for r in rows))
    colours = {"ddim": "#4c72b0", "ddpm": "#dd8452"}
    width = 0.8 / len(samplers)
    fig, ax = plt.subplots(figsize=(1.9 * len(methods) + 1.5, 3.6))
    hatch_label = "projection"
    for j, sampler in enumerate(samplers):
        for i, method in enumerate(methods):
            row = next((r for r in rows if r["method"] == method and r["sampler"] == sampler), None)
            if row is None:
                continue
            x = i + (j - (len(samplers) - 1) / 2) * width
            ax.bar(x, row["median_s"], width * 0.95, color=colours.get(sampler, "#55a868"),
                   label=sampler.upper() if i == 0 else None)
            if row.get("projection_median_s"):
                ax.bar(x, row["projection_median_s"], width * 0.95, fill=False, hatch="///", edgecolor="#333333",
                       label=hatch_label)
                hatch_label = None
            ax.text(x, row["median_s"] * 1.08, f"×{row['median_s'] / ref:.1f}", ha="center", va="bottom", fontsize=8)
    ax.set_yscale("log")
    ax.set_xticks(range(len(methods)), methods)
    ax.set_ylabel("seconds per motion (median)")
    ax.set_title("batch 1; ratio to MDM-DDIM above each bar; hatched: simulator projection", fontsize=9)
    ax.legend(fontsize=8)
    ax.margins(y=0.2)
    return save_figure(fig, path)


def finish(runner: Runner, report: dict[str, Any]) -> list[str]:
    rows = report["rows"]
    t = runner.config.timing
    ref_row = next((r for r in rows if r["sampler"] == "ddim" and r["method"] == "MDM"), rows[0] if rows else None)
    if ref_row is None:
        return ["No rows."]
    ref = ref_row["median_s"]
    report["reference"] = {"method": ref_row["method"], "sampler": ref_row["sampler"], "median_s": ref}
    path = figure(rows, ref, runner.out / "fig4.png")
    lines = [f"Prompt “{t.text}”, {t.length} frames ({t.length / FPS:g} s), batch 1, median of the repeats after "
             f"{t.warmup} warm-up run(s); reference: {ref_row['method']}-{ref_row['sampler'].upper()}.", "",
             "| Method | Sampler | median s/motion | × reference | projection s (median) | repeats | all runs (s) |",
             "|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['method']} | {r['sampler'].upper()} | {r['median_s']:.2f} | ×{r['median_s'] / ref:.2f} | "
                     f"{value(r.get('projection_median_s'), 2)} | {r['repeats']} | "
                     + ", ".join(f"{x:.2f}" for x in r["times_s"]) + " |")
    lines += ["", "SimDiff against PhysDiff, per sampler (median s/motion):"] + (speed_comparison(rows, "median_s") or
                                                                                  ["* (no pair of rows to compare)"])
    m = runner.provenance["machine"]
    loads = [x[0] for x in (m.get("load_avg_start"), m.get("load_avg_end")) if x]
    if loads and max(loads) > (m.get("cpus") or 1):
        lines += ["", f"**Warning:** the machine was busy (1-min load average up to {max(loads):g} on {m['cpus']} CPUs): "
                      "timings include waiting for other jobs; rerun on an idle machine for the figure."]
    lines += ["", f"![inference time]({path.name})"]
    return lines
