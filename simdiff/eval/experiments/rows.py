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
    """Our Phys-Err (mm) = penetration + sliding + |floating − GT floating| of a protocol or subset row.

    PhysDiff's sum adds raw floating, which rewards sinking into the floor; floating is scored as
    the distance to the ground truth's floating instead (:func:`simdiff.motion.metrics.phys_err`).
    The ground-truth row scores penetration + sliding. Rows without ``phys_err`` (cached rows
    written by an older version) give None: they are re-measured, not re-scored.
    """
    if row.get("method") == "Ground truth" and "summary" in row:
        s = row["summary"]
        return s["penetration"]["mean"] + s["sliding"]["mean"] if "penetration" in s and "sliding" in s else None
    if "summary" in row:
        s = row["summary"]
        return s["phys_err"]["mean"] if "phys_err" in s else None
    if "physics" in row:
        return row["physics"].get("phys_err")
    return None


def phys_err_ci(row: dict[str, Any]) -> float:
    """The Student-t half-width of a protocol row's Phys-Err (0 for subset rows)."""
    s = row.get("summary", {})
    return float(s["phys_err"]["ci95"]) if "phys_err" in s and s["phys_err"]["ci95"] == s["phys_err"]["ci95"] else 0.0
