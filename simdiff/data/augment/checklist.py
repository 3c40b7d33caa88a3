"""Quality checks of an augmentation run, evaluated on its numbers (PASS / FAIL / NO DATA).

Each criterion is computed from the report's tables, never written in:

* ``plain_gravity``: keep rate ≥ 50 % at every gravity bin in [−20, −1] for clips without
  acrobatics and without flight (class ``plain``, :mod:`simdiff.data.augment.classes`);
* ``flight_gravity``: ≥ 25 % at every gravity bin for clips with flight (class ``flight``);
* ``wind``: ≥ 60 % at every wind bin (w_x and w_y) over the clips without acrobatics
  (``plain`` and ``flight`` pooled);
* ``earth``: Earth keep rate over all clips ≥ 66 % (that of a filter without the flight clock,
  d_L2 ≤ 7 and residual ≤ 0.1·m·|g_z|; :mod:`simdiff.data.augment.decide`);
* ``confound``: every |r| between a φ component and a content statistic ≤ 0.1;
* ``low_g_flight`` (a proxy on the run's own pairs for the CMU jumps at g = −1.6): over ``flight``
  clips whose Earth rollout flew, pairs in the lowest gravity bin g ∈ [−3, −1): median longest-flight
  ratio to the clip's Earth rollout ≥ 3 and ≥ 70 % tracked to the end.

A bin that has no pair of the class reads NO DATA and fails the overall verdict. Each criterion
is evaluated in every view of the report (all pairs; clips whose Earth rollout tracked).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from simdiff.data.augment.classes import close, new_cell
from simdiff.data.augment.signal import GRAVITY_EDGES, WIND_EDGES, condition_bin

PASS, FAIL, NO_DATA = "PASS", "FAIL", "NO DATA"


@dataclass(frozen=True)
class DoneWhen:
    """The bounds of the quality checks (fractions; |r|; flight ratio)."""

    plain_gravity_keep: float = 0.5
    flight_gravity_keep: float = 0.25
    wind_keep: float = 0.6
    earth_keep: float = 0.66
    confound_r: float = 0.1
    low_g_flight_ratio: float = 3.0
    low_g_landed: float = 0.7


def gravity_bins() -> list[str]:
    """The gravity bin labels covering [−20, −1]."""
    return [condition_bin([(a + b) / 2, 0.0, 0.0]) for a, b in zip(GRAVITY_EDGES, GRAVITY_EDGES[1:])]


def wind_bins() -> list[str]:
    """The w_x and w_y bin labels covering [−10, 10] N."""
    mids = [(a + b) / 2 for a, b in zip(WIND_EDGES, WIND_EDGES[1:])]
    return [condition_bin([-9.81, m, 0.0]) for m in mids] + [condition_bin([-9.81, 0.0, m]) for m in mids]


def _pooled(table: dict[str, dict[str, dict[str, Any]]], b: str, classes: Sequence[str] | None) -> dict[str, Any]:
    cell = new_cell()
    for k, c in table.get(b, {}).items():
        if classes is None or k in classes:
            for key in cell:
                cell[key] += c[key]
    return close(cell)


def _every_bin(table: dict[str, Any], bins: Sequence[str], classes: Sequence[str] | None, bound: float) -> dict[str, Any]:
    """The lowest keep rate over ``bins`` (pooled over ``classes``) against ``bound``."""
    cells = {b: _pooled(table, b, classes) for b in bins}
    empty = [b for b, c in cells.items() if not c["pairs"]]
    rated = {b: c for b, c in cells.items() if c["pairs"]}
    if not rated:
        return {"status": NO_DATA, "value": None, "where": None, "empty_bins": empty}
    worst = min(rated, key=lambda b: rated[b]["kept_fraction"])
    value = rated[worst]["kept_fraction"]
    status = FAIL if value < bound else (NO_DATA if empty else PASS)
    return {"status": status, "value": value, "where": worst, "kept": rated[worst]["kept"],
            "pairs": rated[worst]["pairs"], "failing_bins": sorted(b for b, c in rated.items() if c["kept_fraction"] < bound),
            "empty_bins": empty}


def _earth(table: dict[str, Any], bound: float) -> dict[str, Any]:
    cell = _pooled(table, "earth", None)
    if not cell["pairs"]:
        return {"status": NO_DATA, "value": None}
    v = cell["kept_fraction"]
    return {"status": PASS if v >= bound else FAIL, "value": v, "kept": cell["kept"], "pairs": cell["pairs"]}


def _confound(confound: dict[str, Any], bound: float) -> dict[str, Any]:
    v = confound.get("max_abs_r")
    if v is None:
        return {"status": NO_DATA, "value": None}
    return {"status": PASS if v <= bound else FAIL, "value": v, "where": confound.get("worst"), "pairs": confound["pairs"]}


def low_g_flight(records: Sequence[dict[str, Any]], classes: dict[str, str], clips: set[str] | None,
                 cfg: DoneWhen) -> dict[str, Any]:
    """The low-gravity flight proxy (module docstring) over ``clips`` (None = all)."""
    low = gravity_bins()[-1]
    earth = {r["clip"]: r["signal"] for r in records
             if condition_bin(r["env"]) == "earth" and r.get("signal") and r["signal"].get("flight_s", 0) > 0}
    pairs = [r for r in records if condition_bin(r["env"]) == low and classes.get(r["clip"]) == "flight"
             and r["clip"] in earth and (clips is None or r["clip"] in clips)]
    if not pairs:
        return {"status": NO_DATA, "value": None, "pairs": 0, "where": low}
    landed = [isinstance(r.get("info"), dict) and bool(r["info"].get("success")) for r in pairs]
    ratios = [r["signal"]["flight_s"] / earth[r["clip"]]["flight_s"] for r, ok in zip(pairs, landed) if ok and r.get("signal")]
    ratio = float(np.median(ratios)) if ratios else None
    rate = sum(landed) / len(pairs)
    ok = ratio is not None and ratio >= cfg.low_g_flight_ratio and rate >= cfg.low_g_landed
    return {"status": PASS if ok else FAIL, "value": ratio, "landed": rate, "pairs": len(pairs), "where": low}


def checklist(views: dict[str, dict[str, Any]], confounds: dict[str, dict[str, Any]], records: Sequence[dict[str, Any]],
              classes: dict[str, str], tracked: set[str], cfg: DoneWhen = DoneWhen()) -> dict[str, Any]:
    """Every criterion in every view; ``passes`` is True only when all pass in the ``all`` view.

    Args:
        views: ``{name: view}`` from :func:`simdiff.data.augment.classes.class_view` (``all``,
            ``earth_tracked``).
        confounds: ``{name: confound_check result}`` for the same views.
        records: decided records (for the low-g flight proxy).
        classes: ``{clip: class}``.
        tracked: clips whose Earth rollout tracked.
    """
    gb, wb = gravity_bins(), wind_bins()
    items = [
        ("plain_gravity", f"keep ≥ {cfg.plain_gravity_keep:.0%} at every gravity bin in [−20, −1], clips without "
                          "acrobatics or flight", lambda t: _every_bin(t, gb, ["plain"], cfg.plain_gravity_keep)),
        ("flight_gravity", f"keep ≥ {cfg.flight_gravity_keep:.0%} at every gravity bin, clips with flight (≥ 0.2 s)",
         lambda t: _every_bin(t, gb, ["flight"], cfg.flight_gravity_keep)),
        ("wind", f"keep ≥ {cfg.wind_keep:.0%} at every wind bin, clips without acrobatics",
         lambda t: _every_bin(t, wb, ["plain", "flight"], cfg.wind_keep)),
        ("earth", f"Earth keep ≥ {cfg.earth_keep:.0%}, all clips", lambda t: _earth(t, cfg.earth_keep)),
    ]
    out: list[dict[str, Any]] = []
    for key, text, fn in items:
        out.append({"key": key, "criterion": text, "views": {v: fn(view["table"]) for v, view in views.items()}})
    out.append({"key": "confound", "criterion": f"confound |r| ≤ {cfg.confound_r} for every φ component × content statistic",
                "views": {v: _confound(confounds[v], cfg.confound_r) for v in views}})
    out.append({"key": "low_g_flight",
                "criterion": f"proxy: flight clips at g ∈ [−3, −1) fly ≥ {cfg.low_g_flight_ratio:g}× their Earth rollout "
                             f"(median) and ≥ {cfg.low_g_landed:.0%} track to the end (for the CMU jumps at g = −1.6)",
                "views": {v: low_g_flight(records, classes, None if v == "all" else tracked, cfg) for v in views}})
    verdict = all(i["views"]["all"]["status"] == PASS for i in out) if "all" in views else None
    return {"items": out, "passes": verdict,
            "not_evaluated": ["ballistic fit of apex and flight time",
                              "tests of the time-warped reference, the filter and the confound check (tests/)"]}


def _cell(r: dict[str, Any]) -> str:
    v = r.get("value")
    if v is None:
        return r["status"]
    if "landed" in r:
        return f"{r['status']} {v:.2f}×, tracked {100 * r['landed']:.0f} % ({r['pairs']} pairs)"
    if isinstance(r.get("where"), list):
        return f"{r['status']} |r| = {v:.3f} ({' vs '.join(r['where'])}, {r['pairs']} pairs)"
    where = f" at {r['where']}" if r.get("where") else ""
    more = f"; below: {', '.join(r['failing_bins'])}" if len(r.get("failing_bins") or []) > 1 else ""
    empty = f"; no pairs: {', '.join(r['empty_bins'])}" if r.get("empty_bins") else ""
    return f"{r['status']} {100 * v:.1f} %{where} ({r['kept']}/{r['pairs']}){more}{empty}"


def checklist_markdown(check: dict[str, Any], labels: dict[str, str]) -> list[str]:
    """The checklist as a Markdown table, one column per view (labels: ``{view: column title}``)."""
    views = list(labels)
    verdict = {True: "PASS", False: "FAIL", None: "—"}[check["passes"]]
    lines = [f"Overall (all pairs): **{verdict}**", "",
             "| criterion | " + " | ".join(labels[v] for v in views) + " |", "|---" * (len(views) + 1) + "|"]
    for item in check["items"]:
        cells = [item["criterion"]] + [_cell(item["views"][v]) for v in views]
        lines.append("| " + " | ".join(c.replace("|", "\\|") for c in cells) + " |")
    lines += ["", "Not evaluated from the run's records: " + "; ".join(check["not_evaluated"]) + ".", ""]
    return lines
