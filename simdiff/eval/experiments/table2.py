"""Table 2: the adapter-scale sweep α for SimDiff (T2M protocol + physics metrics per α).

Writes the best α (``report.json["best_alpha"]``) for table1, chosen by ``select_by``:
``balanced`` (default) the lowest mean of FID and Phys-Err, each min–max scaled to [0, 1]
over the sweep (the α nearest the ideal corner of the trade-off; ties: lower FID), ``fid``
the lowest FID, ``phys_err`` the lowest Phys-Err (penetration + sliding + |floating − GT floating|).
Run it on the val split: α is chosen here and reported on test by table1.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from simdiff.errors import SimdiffError
from simdiff.eval.experiments.rows import method_plan, phys_err
from simdiff.eval.experiments.runner import RowPlan, Runner
from simdiff.eval.experiments.tables import alpha_figure, metrics_table

TITLE = "Table 2 — adapter scale α"


def plan(runner: Runner) -> list[RowPlan]:
    c = runner.config
    alphas = [float(a) for a in c.alphas if a != "best"]
    if not alphas:
        raise SimdiffError("table2 needs a list of 'alphas'")
    specs = [m for m in c.models if runner.is_simdiff(m)]
    if not specs:
        raise SimdiffError("table2 needs a SimDiff model (adapters) in 'models'")
    return [method_plan(runner, spec, sampler, a) for spec in specs for sampler in spec.own_samplers(c.samplers) for a in alphas]


def select_alpha(rows: list[dict[str, Any]], select_by: str) -> dict[str, Any] | None:
    """The best α among protocol rows of one method (see module docstring)."""
    rows = [r for r in rows if "summary" in r and "fid" in r["summary"]]
    if not rows:
        return None
    fid = np.array([r["summary"]["fid"]["mean"] for r in rows])
    pe = np.array([phys_err(r) if phys_err(r) is not None else np.inf for r in rows])
    if select_by == "fid":
        score = fid
    elif select_by == "phys_err":
        score = pe
    else:
        def scaled(x: np.ndarray) -> np.ndarray:
            span = x.max() - x.min()
            return (x - x.min()) / span if np.isfinite(span) and span > 0 else np.zeros_like(x)

        score = (scaled(fid) + scaled(pe)) / 2.0
    best = min(range(len(rows)), key=lambda i: (score[i], fid[i]))
    r = rows[best]
    return {"alpha": r["alpha"], "method": r["method"], "sampler": r["sampler"], "select_by": select_by,
            "fid": float(fid[best]), "phys_err": float(pe[best])}


def finish(runner: Runner, report: dict[str, Any]) -> list[str]:
    c = runner.config
    rows = report["rows"]
    best = select_alpha([r for r in rows if r["method"] == rows[0]["method"]], c.select_by) if rows else None
    report["best_alpha"] = best
    figure = alpha_figure(rows, runner.out / "table2.png", best["alpha"] if best else None)
    lines = metrics_table(rows)
    lines += ["", f"Best α by {c.select_by!r}: **{best['alpha']:g}** (FID {best['fid']:.3f}, Phys-Err {best['phys_err']:.2f} mm); "
              "table1 reads it from this report." if best else "No best α: no protocol rows."]
    lines += ["", f"![α sweep]({figure.name})"]
    return lines
