"""The augmentation report: keep rates and rejections per condition bin and per bin × content class
(:mod:`simdiff.data.augment.classes`), the quality checks
(:mod:`simdiff.data.augment.checklist`), confound check, physics signal."""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from typing import Any

from simdiff.data.augment.checklist import checklist, checklist_markdown
from simdiff.data.augment.classes import (bin_key, class_markdown, class_view, clip_classes, close, count,
                                          earth_tracked, new_cell)
from simdiff.data.augment.conditions import AugmentEnv
from simdiff.data.augment.confound import confound_check
from simdiff.data.augment.filter import REASONS, FilterConfig
from simdiff.data.augment.signal import condition_bin, signal_markdown, signal_table


def _env(r: dict[str, Any], by_index: dict[int, AugmentEnv]) -> list[float]:
    if "env" in r:
        return [float(v) for v in r["env"]]
    return list(by_index[r["condition"]].env.as_tuple())


VIEWS: dict[str, str] = {"all": "All pairs",
                         "earth_tracked": "Clips whose Earth rollout tracked (tracker failures at Earth are not φ's doing)"}


def build_report(records: Sequence[dict[str, Any]], conditions: Sequence[AugmentEnv], config: Any,
                 filter_summary: dict[str, Any] | None = None,
                 motion_types: dict[str, str] | None = None) -> dict[str, Any]:
    """Kept fraction and reasons per condition and per condition bin, confound check, signal table.

    Args:
        records: the shards' pair records (``clip``, ``condition``, ``kept``, ``reason``,
            ``info``, and in paired mode ``env``, ``signal``, ``content``).
        conditions: the run's shared condition list (paired mode: Earth only).
        config: the :class:`simdiff.data.augment.run.AugmentConfig`.
        filter_summary: from :func:`simdiff.data.augment.decide.decide`: the thresholds used
            (``thresholds``) and, with ``auto``, the Earth ``calibration``.
        motion_types: ``{clip: motion_type}`` of the corpus manifest (the ``acrobatics`` class,
            :mod:`simdiff.data.augment.classes`); None: no clip counts as acrobatics.

    The per-class views (``by_class``: all pairs, and clips whose Earth rollout tracked) and
    the quality checks (``checklist``, :mod:`simdiff.data.augment.checklist`) are
    computed from the same records.

    Pairs derived from a mirror (``mirrored_from``, ``--share-mirrors``) count in the keep
    rates and the signal table (they are in the corpus) but not in the simulator CPU time (they
    cost none) nor in the confound check (their φ is mirror(original φ), not a draw of its own).
    """
    by_index = {c.index: c for c in conditions}
    if filter_summary is None:
        filter_summary = {"thresholds": dataclasses.asdict(getattr(config, "filter", FilterConfig()))}
    filt = FilterConfig(**filter_summary["thresholds"])
    rows = []
    if config.mode != "paired":
        for cond in conditions:
            mine = [r for r in records if r["condition"] == cond.index]
            reasons = {k: sum(1 for r in mine if r["reason"] == k) for k in REASONS}
            rows.append({**cond.to_dict(), "pairs": len(mine), "kept": reasons["kept"],
                         "kept_fraction": reasons["kept"] / len(mine) if mine else None, "reasons": reasons})
    bins: dict[str, dict[str, Any]] = {}
    for r in records:
        count(bins.setdefault(condition_bin(_env(r, by_index)), new_cell()), r, filt)
    for row in bins.values():
        close(row)
    simulated = [r for r in records if not r.get("mirrored_from")]
    cpu = [float(r["info"].get("cpu_s", 0.0)) for r in simulated if isinstance(r["info"], dict)]
    sim_s = [float(r["info"].get("n_out", 0)) / 20.0 for r in simulated if isinstance(r["info"], dict)]
    total_kept = sum(1 for r in records if r["kept"])
    content = {r["clip"]: r["content"] for r in records if r.get("content")}
    table_in = [{"clip": r["clip"], "env": _env(r, by_index), "kept": r["kept"], "signal": r.get("signal")}
                for r in records]
    drawn = [t for t, r in zip(table_in, records) if t["kept"] and not r.get("mirrored_from")]
    classes = clip_classes(records, motion_types)
    tracked = earth_tracked(records)
    with_env = [{**r, "env": t["env"]} for t, r in zip(table_in, records)]
    views = {v: class_view(with_env, classes, filt, None if v == "all" else tracked, label) for v, label in VIEWS.items()}
    confounds = {"all": confound_check(drawn, content),
                 "earth_tracked": confound_check([t for t in drawn if t["clip"] in tracked], content)}
    return {"settings": config.settings(), "filter": filter_summary, "pairs": len(records), "kept": total_kept,
            "mirrored_pairs": len(records) - len(simulated),
            "kept_fraction": total_kept / len(records) if records else None,
            "clips": len({r["clip"] for r in records}), "sim_cpu_s_total": round(sum(cpu), 3),
            "cpu_s_per_sim_s": round(sum(cpu) / sum(sim_s), 4) if sum(sim_s) > 0 else None,
            "per_condition": rows, "per_bin": dict(sorted(bins.items(), key=lambda kv: bin_key(kv[0]))),
            "confound": confounds["all"], "confound_earth_tracked": confounds["earth_tracked"],
            "motion_types": "manifest" if motion_types is not None else "none (no manifest.json: no acrobatics class)",
            "by_class": views, "checklist": checklist(views, confounds, with_env, classes, tracked),
            "signal": signal_table(table_in)}


def _calibration_lines(cal: dict[str, Any] | None) -> list[str]:
    if cal is None:
        return []
    how = "reached" if cal["reachable"] else "unreachable: every tracked, residual-ok Earth pair kept"
    return [f"* pose d_L2 threshold calibrated on this run's Earth pairs (auto): {cal['max_pose_d_l2']:.4g}; "
            f"Earth keep rate target {100 * cal['earth_keep_target']:.1f} %, achieved "
            f"{100 * cal['earth_keep_achieved']:.1f} % ({cal['earth_kept']}/{cal['earth_pairs']}; {how})"]


def report_markdown(report: dict[str, Any]) -> str:
    """The report as Markdown tables."""
    frac = report["kept_fraction"]
    lines = [
        "# Simulator-augmented corpus", "",
        f"* pairs: {report['pairs']} from {report['clips']} clips; kept {report['kept']}"
        + (f" ({100 * frac:.1f} %)" if frac is not None else ""),
        f"* pairs derived from a mirror (not simulated): {report.get('mirrored_pairs', 0)}",
        f"* filter: {report['filter']['thresholds']}; tracker residual bound {report['settings']['residual_bound']}·m·g",
        *_calibration_lines(report["filter"].get("calibration")),
        f"* simulator CPU time: {report['sim_cpu_s_total']} s ({report.get('cpu_s_per_sim_s')} CPU s per simulated s)", "",
        "## Quality checks (computed from this run)", "",
        *(checklist_markdown(report["checklist"], VIEWS) if "checklist" in report else []),
        "## Keep rate per condition bin (each criterion judged on its own)", "",
        "| bin | pairs | kept | kept % | failed | faithfulness | residual | error |", "|---|---|---|---|---|---|---|---|",
    ]
    for b, r in report["per_bin"].items():
        pct = "—" if r["kept_fraction"] is None else f"{100 * r['kept_fraction']:.1f}"
        lines.append(f"| {b} | {r['pairs']} | {r['kept']} | {pct} | {r['rejected_failed']} | {r['rejected_faithfulness']} "
                     f"| {r['rejected_residual']} | {r['error']} |")
    if "by_class" in report:
        lines += ["", "## Keep rate per condition bin × content class", "",
                  f"Classes: acrobatics = manifest motion_type `acrobatics` (motion types: {report['motion_types']}); "
                  "flight = otherwise, the source's longest flight ≥ 0.2 s by `simdiff.motion.flight` (the corpus "
                  "report's rule, `has_flight`); plain = the rest; unknown = source unreadable.", ""]
        for view in report["by_class"].values():
            lines += class_markdown(view)
    c = report["confound"]
    lines += ["", "## Confound check (φ vs clip content over kept pairs with drawn φ)", "",
              f"* max |r| = {c['max_abs_r'] if c['max_abs_r'] is None else round(c['max_abs_r'], 3)} "
              f"({c['worst']}) over {c['pairs']} pairs; passes (≤ {c['bound']}): {c['passes']}", "",
              "## Physics signal (medians, against each clip's own Earth rollout)", "", signal_markdown(report["signal"])]
    if report["per_condition"]:
        lines += ["## Per condition", "",
                  "| cond | factor | g_z | w_x | w_y | pairs | kept | kept % | failed | faithfulness | residual | error |",
                  "|---|---|---|---|---|---|---|---|---|---|---|---|"]
        for r in report["per_condition"]:
            g, wx, wy = r["env"]
            pct = "—" if r["kept_fraction"] is None else f"{100 * r['kept_fraction']:.1f}"
            rs = r["reasons"]
            lines.append(f"| {r['index']} | {r['factor']} | {g:.2f} | {wx:.2f} | {wy:.2f} | {r['pairs']} | {r['kept']} "
                         f"| {pct} | {rs['failed']} | {rs['faithfulness']} | {rs['residual']} | {rs['error']} |")
    return "\n".join(lines) + "\n"
