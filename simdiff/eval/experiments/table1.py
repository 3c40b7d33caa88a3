"""Table 1: ground truth, MDM, PhysDiff and SimDiff, each with DDPM and DDIM sampling.

SimDiff rows at the paper's α (0.1) and at the best α (``best_alpha`` in the config, else
the ``best_alpha_from`` report, table2; without either the best-α rows are left out and the
report says so). PhysDiff projects at t = 60, 40, 20, 0: End4/Space1 of DDIM-50, the same
original timesteps out of DDPM-1000. DDPM rows follow ``ddpm_samples`` (CPU budget).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from simdiff.eval.experiments.rows import ground_truth_plan, method_plan
from simdiff.eval.experiments.runner import RowPlan, Runner
from simdiff.eval.experiments.report import speed_comparison
from simdiff.eval.experiments.tables import method_figure, metrics_table, paired_differences

TITLE = "Table 1 — MDM, PhysDiff and SimDiff with DDPM and DDIM"


def best_alpha(runner: Runner) -> tuple[float | None, str]:
    """(best α, where it came from), read once per run: the rows and the report agree."""
    if "best_alpha" not in runner.notes:
        runner.notes["best_alpha"] = _read_best_alpha(runner)
    return runner.notes["best_alpha"]


def _read_best_alpha(runner: Runner) -> tuple[float | None, str]:
    c = runner.config
    if c.best_alpha is not None:
        return float(c.best_alpha), "config"
    path = Path(c.out_dir) / c.best_alpha_from / "report.json"
    if path.is_file():
        report = json.loads(path.read_text(encoding="utf-8"))
        best, split = report.get("best_alpha"), report.get("config", {}).get("split")
        if best and split == c.split and not c.smoke:
            return None, (f"refused: {path} chose α on the {split!r} split, the split this table reports on; "
                          "run table2 on val")
        if best:
            return float(best["alpha"]), f"{path} (select_by {best.get('select_by')}, chosen on the {split} split)"
    return None, (f"not available when this run started: no {path} with a best α and no 'best_alpha' in the config; "
                  "run table2 first (simdiff evaluate all does) and run table1 again")


def alphas(runner: Runner, values: list[float | str] | None = None) -> list[tuple[float, str]]:
    """(α, why) for SimDiff rows of ``values`` (None: the table's ``alphas``), duplicates merged (``0.1 (paper, best)``)."""
    out: dict[float, list[str]] = {}
    for a in (runner.config.alphas if values is None else values) or [None]:
        if a == "best":
            value, _ = best_alpha(runner)
            if value is not None:
                out.setdefault(value, []).append("best")
        elif a is None:
            continue
        else:
            out.setdefault(float(a), []).append("paper" if abs(float(a) - 0.1) < 1e-12 else "config")
    return [(a, ", ".join(why)) for a, why in out.items()]


def plan(runner: Runner) -> list[RowPlan]:
    c = runner.config
    plans = [ground_truth_plan(runner)]
    sim_alphas = alphas(runner)
    for spec in c.models:
        for sampler in spec.own_samplers(c.samplers):
            if runner.is_simdiff(spec):
                pairs = (sim_alphas if spec.alphas is None else alphas(runner, spec.alphas)) or [(runner.alpha(spec), "model")]
                plans += [method_plan(runner, spec, sampler, a, alpha_choice=why, compare_to=spec.compare_to)
                          for a, why in pairs]
            else:
                plans.append(method_plan(runner, spec, sampler, None, compare_to=spec.compare_to))
    return plans


def ddpm_note(runner: Runner) -> str:
    """What the DDPM rows measured, in words."""
    c = runner.config
    if c.ddpm_samples == 0:
        return "the same protocol as the DDIM rows"
    if c.ddpm_samples >= c.protocol.batch_size:
        return f"{c.ddpm_samples} test motions, {c.ddpm_replications} replication(s), no MultiModality"
    return f"{c.ddpm_samples} test motions (physics and time only)"


def finish(runner: Runner, report: dict[str, Any]) -> list[str]:
    from simdiff.sim.fallback import FINISH_FALLBACK_SLIDING

    c = runner.config
    value, source = best_alpha(runner)
    report["best_alpha"] = {"alpha": value, "source": source}
    figure = method_figure(report["rows"], runner.out / "table1.png")
    physdiff = [m for m in c.models if m.physdiff is not None]
    lines = metrics_table(report["rows"]) + paired_differences(report["rows"])
    lines += ["", f"* best α: {value if value is not None else '—'} ({source})",
              f"* protocol (DDIM rows): {c.protocol.replications} replications × {runner.samples_per_replication(c.protocol)} "
              f"test motions (batches of {c.protocol.batch_size}, samples_limit {c.protocol.samples_limit}); MultiModality "
              + (f"{c.protocol.mm_prompts} prompts × {c.protocol.mm_repeats} repeats, {c.protocol.mm_times} pairs"
                 if c.protocol.mm_prompts else "off"),
              "* DDPM rows: " + ddpm_note(runner)]
    for m in physdiff:
        for sampler in m.own_samplers(c.samplers):
            cfg = runner.physdiff_config(m, sampler)
            lines.append(f"* {m.name} {sampler.upper()}: projection at t = {', '.join(map(str, cfg.project_at))} "
                         f"({cfg.steps or ('1000' if sampler == 'ddpm' else '50')} steps), residual bound {cfg.residual_bound}")
    for row in report["rows"]:
        if row.get("finish"):
            f = row["finish"]
            second = (f"; {f['second_tries']} had a second try under the slip guard (fell or slid > "
                      f"{FINISH_FALLBACK_SLIDING:g} mm/frame), "
                      f"whose rollout was kept for {f['fallback_kept']}") if "second_tries" in f else ""
            lines.append(f"* {row['method']} {row['sampler'].upper()}: the simulator tracked {f['tracked']} of {f['motions']} "
                         f"final samples to the end ({100 * f['tracked_frac']:.0f} %){second}; after a fall the generated "
                         f"frames stay")
    lines.append("* s/motion: generation time per motion in the protocol's batches of 32 (PhysDiff: with projection); "
                 "see fig4 for batch-1 latency")
    lines += speed_comparison(report["rows"], "s_per_motion")
    lines += ["", f"![Table 1]({figure.name})"]
    return lines
