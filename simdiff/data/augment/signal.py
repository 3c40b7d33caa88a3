"""The physics signal of an augmented corpus: what φ changed, against each clip's own Earth rollout.

:func:`measure` reads a motion (T, 22, 3) (HumanML3D joints, metres, Y-up, 20 fps, in the
source's frame, so that wind directions are those of φ): flights (the one offline rule,
:mod:`simdiff.motion.flight`), apex, steps, drift.
:func:`signal_table` aggregates, per condition bin, over kept pairs whose clip's Earth rollout
was also tracked: apex and flight-time change on clips with flight, step length and cadence
change on walks/runs, and the horizontal drift along the wind per 10 N.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from simdiff.motion.flight import FEET, feet_up, flight_stats

GRAVITY_EDGES: tuple[float, ...] = (-20.0, -15.0, -11.0, -8.5, -5.0, -3.0, -1.0)
WIND_EDGES: tuple[float, ...] = (-10.0, -5.0, 0.0, 5.0, 10.0)


def measure(joints: np.ndarray, fps: float = 20.0) -> dict[str, float]:
    """Physical measurements of one motion.

    Args:
        joints: (T, 22, 3) metres, Y-up, ``fps`` frames per second.
    Returns:
        duration_s; flights (count), flight_s (longest, s), flight_total_s, apex_gain_m (root
        height gain over take-off in the longest flight), all from :mod:`simdiff.motion.flight`;
        apex_m (highest root); speed (mean horizontal root speed, m/s); steps (foot
        touchdowns), cadence (touchdowns per second), step_length_m (mean horizontal distance
        between successive touchdowns of alternating feet); drift_x, drift_z (root
        displacement first → last frame along HumanML3D X and Z, m).
    Raises:
        SimdiffError: not (T, 22, 3) with T ≥ 2.
    """
    j = np.asarray(joints, dtype=np.float64)
    stats = flight_stats(j, fps)
    T = j.shape[0]
    root = j[:, 0]
    out: dict[str, float] = {"duration_s": (T - 1) / fps, **stats, "apex_m": float(root[:, 1].max())}
    out["speed"] = float(np.linalg.norm(np.diff(root[:, [0, 2]], axis=0), axis=1).mean() * fps)
    # touchdowns: a foot (ankle or toe joint) that comes down after being up
    up = feet_up(j)
    down = ~(up[:, [0, 1]].all(axis=1)), ~(up[:, [2, 3]].all(axis=1))
    events: list[tuple[int, int]] = []
    for side, d in enumerate(down):
        for t in range(1, T):
            if d[t] and not d[t - 1]:
                events.append((t, side))
    events.sort()
    out["steps"] = float(len(events))
    out["cadence"] = len(events) / out["duration_s"] if out["duration_s"] > 0 else 0.0
    lengths = []
    for (t0, s0), (t1, s1) in zip(events, events[1:]):
        if s0 != s1:
            p0 = j[t0, FEET[2 * s0], [0, 2]]
            p1 = j[t1, FEET[2 * s1], [0, 2]]
            lengths.append(float(np.linalg.norm(p1 - p0)))
    out["step_length_m"] = float(np.mean(lengths)) if lengths else 0.0
    out["drift_x"] = float(root[-1, 0] - root[0, 0])
    out["drift_z"] = float(root[-1, 2] - root[0, 2])
    return out


def condition_bin(env: Sequence[float]) -> str:
    """Bin label of φ = (g_z, w_x, w_y): ``earth``, ``g[lo,hi)``, ``wx[lo,hi)`` or ``wy[lo,hi)``."""
    g, wx, wy = (float(v) for v in env)
    if wx == 0 and wy == 0:
        if abs(g + 9.81) < 1e-6:
            return "earth"
        edges, v, name = GRAVITY_EDGES, g, "g"
    elif wx != 0:
        edges, v, name = WIND_EDGES, wx, "wx"
    else:
        edges, v, name = WIND_EDGES, wy, "wy"
    i = int(np.clip(np.searchsorted(edges, v, side="right") - 1, 0, len(edges) - 2))
    return f"{name}[{edges[i]:g},{edges[i + 1]:g})"


def _median(x: list[float]) -> float | None:
    return float(np.median(x)) if x else None


def signal_table(records: Sequence[dict[str, Any]]) -> dict[str, dict[str, Any]]:
    """Per condition bin: physics signal over kept pairs against the clip's own Earth rollout.

    Args:
        records: one per pair with ``clip``, ``env`` (g_z, w_x, w_y), ``kept`` and ``signal``
            (:func:`measure` of the rollout; absent when the rollout failed). A clip's Earth
            record is the one with φ = Earth; it counts when it tracked (has ``signal``).
    Returns:
        {bin: {pairs, kept, d_apex_m, d_flight_s (medians over clips with an Earth flight ≥
        0.1 s), flight_ratio, d_step_length_m, d_cadence (walks/runs: Earth speed > 0.5 m/s
        and ≥ 2 steps), drift_per_10n_m (median drift along the wind relative to Earth, per
        10 N), n_flight, n_gait, n_wind}}.
    """
    earth = {r["clip"]: r["signal"] for r in records
             if condition_bin(r["env"]) == "earth" and r.get("signal")}
    table: dict[str, dict[str, Any]] = {}
    for r in records:
        b = condition_bin(r["env"])
        row = table.setdefault(b, {"pairs": 0, "kept": 0, "_apex": [], "_flight": [], "_ratio": [], "_step": [],
                                   "_cad": [], "_drift": []})
        row["pairs"] += 1
        if not r.get("kept"):
            continue
        row["kept"] += 1
        base, sig = earth.get(r["clip"]), r.get("signal")
        if b == "earth" or base is None or not sig:
            continue
        if base["flight_s"] >= 0.1:
            row["_apex"].append(sig["apex_gain_m"] - base["apex_gain_m"])
            row["_flight"].append(sig["flight_s"] - base["flight_s"])
            row["_ratio"].append(sig["flight_s"] / base["flight_s"])
        if base["speed"] > 0.5 and base["steps"] >= 2:
            row["_step"].append(sig["step_length_m"] - base["step_length_m"])
            row["_cad"].append(sig["cadence"] - base["cadence"])
        _, wx, wy = (float(v) for v in r["env"])
        w = np.array([wx, wy])
        if np.linalg.norm(w) > 0:
            d = np.array([sig["drift_x"] - base["drift_x"], sig["drift_z"] - base["drift_z"]])
            row["_drift"].append(float(d @ w / np.linalg.norm(w) * 10.0 / np.linalg.norm(w)))
    out = {}
    for b in sorted(table):
        row = table[b]
        out[b] = {"pairs": row["pairs"], "kept": row["kept"],
                  "keep_rate": row["kept"] / row["pairs"] if row["pairs"] else None,
                  "d_apex_m": _median(row["_apex"]), "d_flight_s": _median(row["_flight"]),
                  "flight_ratio": _median(row["_ratio"]), "d_step_length_m": _median(row["_step"]),
                  "d_cadence": _median(row["_cad"]), "drift_per_10n_m": _median(row["_drift"]),
                  "n_flight": len(row["_flight"]), "n_gait": len(row["_step"]), "n_wind": len(row["_drift"])}
    return out


def signal_markdown(table: dict[str, dict[str, Any]]) -> str:
    """The table of :func:`signal_table` as Markdown (medians; — where no pair qualifies)."""
    def f(v: Any, nd: int = 3) -> str:
        return "—" if v is None else f"{v:.{nd}f}"

    lines = ["| bin | pairs | kept | keep % | Δapex m | Δflight s | flight × | Δstep m | Δcadence /s | drift per 10 N m | n flight / gait / wind |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for b, r in table.items():
        pct = "—" if r["keep_rate"] is None else f"{100 * r['keep_rate']:.0f}"
        lines.append(f"| {b} | {r['pairs']} | {r['kept']} | {pct} | {f(r['d_apex_m'])} | {f(r['d_flight_s'])} "
                     f"| {f(r['flight_ratio'], 2)} | {f(r['d_step_length_m'])} | {f(r['d_cadence'], 2)} "
                     f"| {f(r['drift_per_10n_m'])} | {r['n_flight']} / {r['n_gait']} / {r['n_wind']} |")
    return "\n".join(lines) + "\n"
