"""Report writing shared by the experiments: header (provenance, budget, paths, time) and cells."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from simdiff.fsio import atomic_path

T2M_METRICS: tuple[tuple[str, str], ...] = (
    ("r_precision_top1", "R@1↑"), ("r_precision_top2", "R@2↑"), ("r_precision_top3", "R@3↑"), ("fid", "FID↓"),
    ("mm_dist", "MM-Dist↓"), ("diversity", "Diversity→"), ("multimodality", "MModality↑"))
PHYSICS_METRICS: tuple[tuple[str, str], ...] = (
    ("penetration", "Penetrate (mm)↓"), ("floating", "Float (mm)→GT"), ("floating_to_gt", "|Float−GT| (mm)↓"),
    ("sliding", "Slide (mm/frame)↓"), ("skate_ratio", "Skate ratio↓"), ("own_floor", "Own floor (mm)→0"),
    ("sliding_own_floor", "Slide on own floor (mm/frame)↓"))
PHYS_ERR_NOTE: str = ("Phys-Err = penetration + sliding + |floating − ground truth's floating| (mm). PhysDiff adds raw "
                      "floating, so a motion that sinks into the floor scores better than the ground truth; floating is "
                      "'→' (closer to ground truth is better), so it enters as its distance to the ground truth's "
                      "floating on the same captions.")
OWN_FLOOR_NOTE: str = ("Slide counts a lowest joint as in contact only within 5 mm of y = 0, so motion that hovers "
                       "scores 0 however its feet skate (and Phys-Err, which adds Slide, rewards hovering). 'Own floor' is "
                       "the 5th percentile of each motion's lowest-joint height (mm above y = 0, mean over motions); 'Slide "
                       "on own floor' is the same sliding after moving each motion's own floor to y = 0 "
                       "(simdiff.motion.metrics.own_floor_metrics).")
INTERVAL_NOTE: str = ("± is the Student-t 95 % half-width over the R replications (t_{0.975,R−1}·s/√R, sample std); "
                      "n × R: motions per replication × replications.")
FID_NOTE: str = ("FID is biased upwards at small n (covariance rank ≤ n − 1 in a D-dimensional embedding): read a "
                 "generated row's FID against the ground-truth row's, which compares two independent draws of the "
                 "test motions at the same n (its FID floor).")
METRIC_LABELS: dict[str, str] = dict(T2M_METRICS + PHYSICS_METRICS)


def mean_ci(summary: dict[str, Any] | None, key: str, digits: int = 3) -> str:
    """``mean ± ci95`` of a protocol summary entry (``—`` when absent; no ± for a single replication)."""
    if not summary or key not in summary:
        return "—"
    s = summary[key]
    if s.get("n", 2) < 2:
        return f"{s['mean']:.{digits}f}"
    return f"{s['mean']:.{digits}f} ± {s['ci95']:.{digits}f}"


def value(x: Any, digits: int = 3) -> str:
    """A number with ``digits`` decimals (``—`` for None/NaN)."""
    if x is None or (isinstance(x, float) and x != x):
        return "—"
    return f"{x:.{digits}f}"


def fmt_env(env: Any) -> str:
    """φ as ``(g, wx, wy)``."""
    if env is None:
        return "—"
    return "(" + ", ".join(f"{float(v):g}" for v in env) + ")"


PAPER_SPEEDUP_NOTE: str = "the paper reports SimDiff DDIM about 10× faster than PhysDiff DDIM"


def speed_comparison(rows: list[dict[str, Any]], key: str, a: str = "SimDiff", b: str = "PhysDiff") -> list[str]:
    """One line per sampler comparing method ``a`` with ``b`` on the seconds in ``key`` (faster or slower, ×)."""
    lines = []
    for sampler in dict.fromkeys(r.get("sampler") for r in rows if r.get("sampler")):
        ra = next((r for r in rows if r["method"] == a and r.get("sampler") == sampler and r.get(key)), None)
        rb = next((r for r in rows if r["method"] == b and r.get("sampler") == sampler and r.get(key)), None)
        if ra is None or rb is None:
            continue
        ratio = rb[key] / ra[key]
        word = f"{ratio:.1f}× faster than" if ratio >= 1 else f"{1 / ratio:.1f}× slower than"
        note = f" ({PAPER_SPEEDUP_NOTE}; here it is {ratio:.1f}×)" if sampler == "ddim" else ""
        lines.append(f"* {sampler.upper()}: {a} ({ra[key]:.2f} s/motion) is {word} {b} ({rb[key]:.2f} s/motion){note}")
    return lines


def duration(seconds: float) -> str:
    """Seconds as ``42 s``, ``3.5 min`` or ``2.1 h``."""
    if seconds < 90:
        return f"{seconds:.0f} s"
    if seconds < 5400:
        return f"{seconds / 60:.1f} min"
    return f"{seconds / 3600:.1f} h"


def header(report: dict[str, Any], title: str) -> list[str]:
    """Title, provenance, budget, resolved paths and measured/estimated time."""
    p = report["provenance"]
    m = p["machine"]
    b = report["budget"]
    rows = report["rows"]
    measured = sum(r.get("wall_s") or 0.0 for r in rows if not r.get("reused_from"))
    estimate = sum(r.get("estimate_s") or 0.0 for r in rows if not r.get("reused_from"))
    lines = [f"# {title}", "",
             f"* command: `{p['command']}` (in `{p.get('cwd', '?')}`)",
             f"* git commit: {p['git_commit']}{' (dirty tree)' if p['git_dirty'] else ''}",
             f"* seed: {p['seed']}",
             f"* machine: {m['host']}, {m['platform']}, {m['cpus']} CPUs ({m.get('torch_threads', '?')} torch threads), "
             f"torch {m['torch']}, {m['device']} ({m['device_name']})",
             f"* started {p['started']}, finished {p['finished']}; load average (1, 5, 15 min) at start "
             f"{m.get('load_avg_start')}, at end {m.get('load_avg_end')}",
             f"* budget: **{b['name']}**" + (f" — {b['about']}" if b.get("about") else ""),
             f"* config: `{report['config'].get('source', '')}`"]
    if b.get("set"):
        lines.append("* budget overrides: " + ", ".join(f"`{k}={v}`" for k, v in b["set"].items()))
    cfg = report["config"]
    if cfg.get("smoke") or b["name"] != "full":
        lines.append(f"* **no claim**: {'a smoke run' if cfg.get('smoke') else 'budget ' + repr(b['name'])} — below the "
                     "claim protocol (n ≥ 256 motions or the whole split per replication, ≥ 5 replications, DDPM rows "
                     "on ≥ 32 motions, α chosen on val); read these numbers as a check that the code runs")
    lines.append("* paths: " + ", ".join(f"{k} `{v}`" for k, v in report["paths"].items()))
    lines.append(f"* rows: {len(rows)} ({sum(1 for r in rows if r.get('reused_from'))} reused from other reports); "
                 f"measurement time {duration(measured)} (estimated {duration(estimate)})")
    return lines + [""]


def save_figure(fig: Any, path: Path, dpi: int = 110) -> Path:
    """Lay out a matplotlib figure, write it to ``path`` atomically and close it; returns ``path``."""
    import matplotlib.pyplot as plt

    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=dpi)
    plt.close(fig)
    return path
