"""Text fidelity on captions training never saw, next to the whole split's.

The corpus splits by take, but its captions repeat across takes: most test items share a caption with a train
item, so the usual protocol mostly measures captions the model (and the evaluator) learned. Here every row runs
twice: on the split's items with all their captions (``all``), and on the items whose captions no train clip has
after normalisation (``unseen``: :func:`simdiff.data.humanml3d.normalise_caption`; an item keeps only such
captions). Ground truth and each method, the same protocol (R-precision, FID, MM-Dist, Diversity,
MultiModality), mean ± 95 % CI over replications; the ratio of a method's R@3 to ground truth's on the same set.
"""

from __future__ import annotations

import dataclasses
import json
from collections import Counter
from collections.abc import Callable
from pathlib import Path
from typing import Any

from simdiff.eval.experiments.report import T2M_METRICS, mean_ci
from simdiff.eval.experiments.rows import ground_truth_plan, method_plan
from simdiff.eval.experiments.runner import CAPTION_SETS, RowPlan, Runner

TITLE = "Held-out captions — text fidelity on captions training never saw"


def _on(captions: str, measure: Callable[[Runner], dict[str, Any]]) -> Callable[[Runner], dict[str, Any]]:
    """``measure`` run with the runner drawing from caption set ``captions``; the row records the set's size."""

    def run(runner: Runner) -> dict[str, Any]:
        before, runner.captions = runner.captions, captions
        try:
            items = runner.dataset.items
            return {**measure(runner), "items": len(items), "types": _types(runner, [it.clip_id for it in items]),
                    "distinct_captions": len({c.text for it in items for c in it.captions})}
        finally:
            runner.captions = before

    return run


def _types(runner: Runner, clip_ids: list[str]) -> dict[str, int]:
    """Items per motion type (the corpus's ``manifest.json``; empty without one)."""
    path = Path(runner.config.corpus).expanduser() / "manifest.json"
    if not path.is_file():
        return {}
    kind = {c["id"]: c.get("motion_type", "?") for c in json.loads(path.read_text(encoding="utf-8"))["clips"]}
    return dict(Counter(kind.get(i, "?") for i in clip_ids).most_common())


def _relabel(plan: RowPlan, captions: str) -> RowPlan:
    return dataclasses.replace(plan, key=f"{plan.key}_{captions}", meta={**plan.meta, "captions": captions},
                               inputs={**plan.inputs, "captions": captions, "unseen_in": "train"},
                               measure=_on(captions, plan.measure))


def plan(runner: Runner) -> list[RowPlan]:
    c = runner.config
    plans = []
    for captions in CAPTION_SETS:
        plans.append(_relabel(ground_truth_plan(runner), captions))
        for spec in c.models:
            alpha = runner.alpha(spec) if runner.is_simdiff(spec) else None
            plans.append(_relabel(method_plan(runner, spec, "ddim", alpha), captions))
    return plans


def finish(runner: Runner, report: dict[str, Any]) -> list[str]:
    c = runner.config
    rows = report["rows"]
    gt = {r["captions"]: r for r in rows if r["method"] == "Ground truth"}
    lines = [(f"The {c.split} split; `all`: every item with all its captions; `unseen`: the items with a caption no "
              "train clip has (normalised), with only those captions. Mean ± 95 % CI over the replications; n × R: "
              "motions per replication × replications (at most the set's whole batches). R@3 / GT: the method's R@3 "
              "over ground truth's on the same set. DDIM; Earth gravity and no wind unless the method names φ. The "
              "sets differ in make-up as well as in captions (items per motion type below), so a drop from `all` to "
              "`unseen` is not only the captions' novelty."), "",
             "| method | captions | items (distinct captions) | n × R | " + " | ".join(l for _, l in T2M_METRICS)
             + " | R@3 / GT |", "|---|---|---|---|" + "---|" * (len(T2M_METRICS) + 1)]
    for r in rows:
        s = r["summary"]
        ref = gt.get(r["captions"])
        ratio = "—"
        if ref is not None and r is not ref:
            ratio = f"{s['r_precision_top3']['mean'] / ref['summary']['r_precision_top3']['mean']:.2f}"
        lines.append(f"| {r['method']} | {r['captions']} | {r['items']} ({r['distinct_captions']}) | "
                     f"{r['samples_per_replication']} × {r['replications_run']} | "
                     + " | ".join(mean_ci(s, k) for k, _ in T2M_METRICS) + f" | {ratio} |")
    for r in rows:
        if r["method"] == "Ground truth" and r.get("types"):
            lines.append(f"\n* items per motion type, {r['captions']} captions: "
                         + ", ".join(f"{k} {v}" for k, v in sorted(r["types"].items(), key=lambda kv: -kv[1])))
    return lines
