"""Markdown and figure helpers for protocol tables (table1, table2)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from simdiff.eval.experiments.report import (FID_NOTE, INTERVAL_NOTE, METRIC_LABELS, OWN_FLOOR_NOTE, PHYS_ERR_NOTE,
                                          PHYSICS_METRICS, T2M_METRICS, mean_ci, save_figure, value)
from simdiff.eval.experiments.rows import phys_err, phys_err_ci


def metrics_table(rows: list[dict[str, Any]], first: str = "Method") -> list[str]:
    """One Markdown row per measured row: T2M metrics, physics metrics, Phys-Err, s/motion (mean ± 95% CI)."""
    cols = [label for _, label in T2M_METRICS] + [label for _, label in PHYSICS_METRICS]
    lines = [f"| {first} | Sampler | α | n × R | " + " | ".join(cols) + " | Phys-Err (mm)↓ | s/motion |",
             "|" + "---|" * (len(cols) + 6)]
    for r in rows:
        alpha = "—" if r.get("alpha") is None else f"{r['alpha']:g}" + (f" ({r['alpha_choice']})" if r.get("alpha_choice") else "")
        sampler = (r.get("sampler") or "—").upper()
        if "summary" in r:
            s = r["summary"]
            n = f"{r['samples_per_replication']} × {r['replications_run']}"
            if r.get("split_size") is not None and r["samples_per_replication"] >= (r["split_size"] // 32) * 32 \
                    and r["samples_per_replication"] < 256:
                n += " (whole split)"
            cells = [mean_ci(s, k) for k, _ in T2M_METRICS] + [mean_ci(s, k) for k, _ in PHYSICS_METRICS]
        else:
            p = r.get("physics", {})
            n = f"{r.get('samples', '?')} × 1 †"
            cells = ["—"] * len(T2M_METRICS) + [value(p.get(k)) for k, _ in PHYSICS_METRICS]
        sps = value(r.get("s_per_motion"), 2) if r.get("s_per_motion") is not None else "—"
        lines.append(f"| {r['method']} | {sampler} | {alpha} | {n} | " + " | ".join(cells) +
                     f" | {value(phys_err(r), 2)} | {sps} |")
    if any("summary" not in r for r in rows):
        lines += ["", "† physics metrics and time only: too few motions for R-precision (batches of 32), FID or Diversity."]
    lines += ["", f"* {INTERVAL_NOTE}", f"* {PHYS_ERR_NOTE}", f"* {OWN_FLOOR_NOTE}", f"* {FID_NOTE}"]
    seeds = next((r["seeds"] for r in rows if r.get("seeds")), None)
    if seeds:
        lines.append(f"* seeds: protocol base seed {seeds.get('base', seeds)}; replication r draws its data with "
                     "[seed, r] and generates batch k with seed·1000003 + r·1009 + k (listed per row in report.json).")
    return lines


def alpha_figure(rows: list[dict[str, Any]], path: Path, best: float | None = None) -> Path:
    """FID, R@3, Phys-Err and skate ratio against α (log axis), mean ± 95% CI."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    keys = [("fid", "FID ↓"), ("r_precision_top3", "R-precision top-3 ↑"), ("phys_err", "Phys-Err (mm) ↓"),
            ("skate_ratio", "skate ratio ↓")]
    fig, axes = plt.subplots(1, len(keys), figsize=(3.3 * len(keys), 3.1))
    for ax, (key, title) in zip(axes, keys):
        for method in dict.fromkeys(r["method"] for r in rows):
            mine = sorted((r for r in rows if r["method"] == method and "summary" in r), key=lambda r: r["alpha"])
            xs = [r["alpha"] for r in mine]
            if key == "phys_err":
                pe = [phys_err(r) for r in mine]
                ys, es = [float("nan") if v is None else v for v in pe], [phys_err_ci(r) for r in mine]
            else:
                ys, es = [r["summary"][key]["mean"] for r in mine], [r["summary"][key]["ci95"] for r in mine]
            ax.errorbar(xs, ys, yerr=es, fmt="o-", capsize=3, label=method)
        if best is not None:
            ax.axvline(best, color="#999999", ls="--", lw=1)
        ax.set_xscale("log")
        ax.set_xlabel("adapter scale α")
        ax.set_title(title, fontsize=10)
    axes[0].legend(fontsize=8)
    return save_figure(fig, path)


def method_figure(rows: list[dict[str, Any]], path: Path) -> Path:
    """Two bar panels per row: FID (protocol rows) and Phys-Err (all rows)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    labels = [r["method"] + (f"\n{r['sampler'].upper()}" if r.get("sampler") else "")
              + (f" α={r['alpha']:g}" if r.get("alpha") is not None else "") for r in rows]
    fig, axes = plt.subplots(1, 2, figsize=(max(8.0, 1.5 * len(rows)), 3.6))
    fid = [r["summary"]["fid"]["mean"] if "summary" in r and "fid" in r["summary"] else 0.0 for r in rows]
    fid_err = [r["summary"]["fid"]["ci95"] if "summary" in r and "fid" in r["summary"] else 0.0 for r in rows]
    pe = [phys_err(r) or 0.0 for r in rows]
    axes[0].bar(range(len(rows)), fid, yerr=fid_err, color="#4c72b0", capsize=3)
    axes[0].set_title("FID ↓ (DDPM subset rows: not measured)", fontsize=9)
    axes[1].bar(range(len(rows)), pe, color="#dd8452")
    axes[1].set_title("Phys-Err = penetrate + slide + |float − GT float| (mm) ↓", fontsize=9)
    for ax in axes:
        ax.set_xticks(range(len(rows)), labels, fontsize=7, rotation=45, ha="right")
    return save_figure(fig, path)


PAIRED_METRICS: tuple[str, ...] = ("r_precision_top3", "fid", "mm_dist", "diversity", "floating_to_gt", "sliding",
                                   "skate_ratio")
"""Metrics of the paired comparisons."""


def paired_differences(rows: list[dict[str, Any]]) -> list[str]:
    """Each protocol row of a method with ``compare_to`` minus that method's row of the same sampler and α, paired by
    replication (same test captions, lengths and noise seeds): mean ± 95 % t-interval over replications."""
    from simdiff.eval.stats import t_interval

    lines = []
    for r in rows:
        ref = next((q for q in rows if r.get("compare_to") and q.get("method") == r["compare_to"]
                    and q.get("sampler") == r.get("sampler") and q.get("alpha") == r.get("alpha")
                    and "replications" in q), None)
        if ref is None or "replications" not in r:
            continue
        pairs = list(zip(r["replications"], ref["replications"]))
        cells = []
        for key in PAIRED_METRICS:
            mean, half = t_interval([a[key] - b[key] for a, b in pairs])
            cells.append(f"{METRIC_LABELS[key]} {mean:+.3f} ± {half:.3f}")
        lines.append(f"* {r['method']} − {ref['method']} ({len(pairs)} paired replications): " + "; ".join(cells))
    return (["", "Paired differences (same captions and seeds; an interval that holds 0 is a difference within "
             "noise):"] + lines) if lines else []
