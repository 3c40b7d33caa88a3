"""Row plans shared by the tables: one method under the T2M protocol (or a DDPM subset), ground truth."""

from __future__ import annotations

import dataclasses
from typing import Any

from simdiff.eval.experiments.config import ModelSpec
from simdiff.eval.experiments.runner import RowPlan, Runner, safe


def method_key(spec: ModelSpec, sampler: str, alpha: float | None, suffix: str = "") -> str:
    """``SimDiff_ddim_alpha0.1`` style row key."""
    return safe(f"{spec.name}_{sampler}" + (f"_alpha{alpha:g}" if alpha is not None else "") + suffix)


def method_plan(runner: Runner, spec: ModelSpec, sampler: str, alpha: float | None, **meta: Any) -> RowPlan:
    """One method row: the full protocol, or for DDPM what ``ddpm_samples`` allows.

    Args:
        alpha: adapter strength (None for models without adapters).
        meta: extra labels for the row (e.g. ``alpha_choice``).
    """
    c = runner.config
    proto = c.protocol if sampler == "ddim" else runner.ddpm_protocol()
    labels = {"method": spec.name, "sampler": sampler, "alpha": alpha, **meta}
    base = {**runner.data_inputs(), **runner.method_inputs(spec, sampler, alpha)}
    if proto is None:
        n = c.ddpm_samples
        labels["measured"] = "subset"
        return RowPlan(method_key(spec, sampler, alpha), labels, {"row": "subset", "samples": n, **base},
                       runner.motion_seconds(spec, sampler, n),
                       lambda r: r.subset_measure(spec, sampler, alpha, n))
    labels["measured"] = "protocol"
    return RowPlan(method_key(spec, sampler, alpha), labels, {"row": "protocol", "protocol": dataclasses.asdict(proto), **base},
                   runner.protocol_seconds(spec, sampler, proto),
                   lambda r: r.protocol_measure(spec, sampler, alpha, protocol=proto))


def ground_truth_plan(runner: Runner) -> RowPlan:
    """The ground-truth row (test motions against a second draw of themselves)."""
    proto = runner.config.protocol
    return RowPlan("ground_truth", {"method": "Ground truth", "sampler": None, "alpha": None, "measured": "protocol"},
                   {"row": "ground_truth", "protocol": dataclasses.asdict(proto), **runner.data_inputs()},
                   runner.protocol_seconds(None, "ddim", proto), lambda r: r.gt_measure())


def phys_err(row: dict[str, Any]) -> float | None:
    """PhysDiff's Phys-Err = penetration + floating + sliding (mm), from a protocol or subset row."""
    if "summary" in row:
        s = row["summary"]
        keys = ("penetration", "floating", "sliding")
        return sum(s[k]["mean"] for k in keys) if all(k in s for k in keys) else None
    if "physics" in row:
        p = row["physics"]
        return p["penetration"] + p["floating"] + p["sliding"]
    return None
