"""Environment response: does a generated motion respond to φ the way physics says that motion should?

For one motion unit u (a prompt × seed) the model generates under Earth φ₀ = (−9.81, 0, 0) and
under each φ of a grid (the same noise), and the simulator re-tracks the *Earth* motion under
φ₀ and under each φ. Per physical quantity q (:func:`quantities`):

* generated effect ``Δg(u, φ) = q(gen_φ) − q(gen_φ₀)``;
* simulated effect ``Δs(u, φ) = q(sim_φ(gen_φ₀)) − q(sim_φ₀(gen_φ₀))``: the physically right answer
  for that motion (both rollouts tracked, so tracking artefacts cancel).

Scores per (factor, quantity), over the pairs (u, φ) whose two rollouts tracked to the end:

* sign agreement: fraction of pairs with ``|Δs| > tolerance`` where ``sign Δg = sign Δs``;
* slope ratio: the through-origin least-squares slope ``Σ Δg·Δs / Σ Δs²`` (1: the size physics
  gives; 0: no response, as an env-blind model must score); undefined (NaN) when no pair has a
  physical effect above the tolerance (a ratio to a null effect is noise);
* additivity error (combinations φ = (g, w_x, w_y)): ``|Δ(φ) − Σ Δ(single-factor parts)|``, for
  the generated and for the simulated motions (the simulator's own non-additivity is the reference).

Intervals: percentile bootstrap over units (:func:`simdiff.eval.stats.bootstrap_interval`), seeded.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from simdiff.errors import SimdiffError
from simdiff.eval.stats import bootstrap_interval

EARTH: tuple[float, float, float] = (-9.81, 0.0, 0.0)
QUANTITIES: dict[str, tuple[str, ...]] = {
    "gravity": ("apex_m", "flight_s", "step_length_m"),
    "wind": ("drift_along_wind_m",),
    "combo": ("apex_m", "flight_s", "step_length_m", "drift_x_m", "drift_z_m"),
}
"""Quantities scored per factor (a φ that changes gravity only, wind only, or both)."""
TOLERANCE: dict[str, float] = {"apex_m": 0.01, "flight_s": 0.05, "step_length_m": 0.02, "drift_along_wind_m": 0.02,
                               "drift_x_m": 0.02, "drift_z_m": 0.02}
"""|Δs| below this is no physical effect: such pairs do not count for sign agreement."""


def factor(env: Sequence[float]) -> str:
    """``earth``, ``gravity``, ``wind`` or ``combo`` for φ = (g_z, w_x, w_y)."""
    g, wx, wy = (float(v) for v in env)
    windy = wx != 0.0 or wy != 0.0
    g_changed = abs(g - EARTH[0]) > 1e-9
    if not windy:
        return "gravity" if g_changed else "earth"
    return "combo" if g_changed else "wind"


def quantities(joints: np.ndarray, env: Sequence[float], fps: float = 20.0) -> dict[str, float]:
    """Physical quantities of one motion (T, 22, 3), metres, Y-up, 20 fps, frame of φ's wind.

    apex_m: highest root height; flight_s: longest flight (the offline rule of
    :mod:`simdiff.motion.flight`, ground estimated per foot joint, so an offset floor is fine);
    step_length_m: mean step length (:func:`simdiff.data.augment.signal.measure`); drift_x_m / drift_z_m: root displacement first →
    last frame; drift_along_wind_m: that displacement along φ's wind direction (0 without wind).
    """
    from simdiff.data.augment.signal import measure

    m = measure(joints, fps)
    _, wx, wy = (float(v) for v in env)
    w = np.array([wx, wy])
    norm = float(np.linalg.norm(w))
    along = float(np.array([m["drift_x"], m["drift_z"]]) @ w / norm) if norm > 0 else 0.0
    return {"apex_m": m["apex_m"], "flight_s": m["flight_s"], "step_length_m": m["step_length_m"],
            "drift_x_m": m["drift_x"], "drift_z_m": m["drift_z"], "drift_along_wind_m": along}


def effects(records: Sequence[dict[str, Any]]) -> list[dict[str, Any]]:
    """Per (unit, φ ≠ Earth): generated and simulated effects against the unit's Earth records.

    Args:
        records: one per (unit, φ) with ``unit`` (hashable id), ``env``, ``gen`` (:func:`quantities` of
            the motion generated under φ) and ``sim`` (:func:`quantities` of the unit's Earth motion
            re-tracked under φ, or None when that rollout did not track to the end).
    Returns:
        dicts with unit, env, factor, ``dgen`` and ``dsim`` ({quantity: effect}; ``dsim`` None when
        either rollout failed). Drift along the wind is taken along φ's wind for both.
    """
    earth = {r["unit"]: r for r in records if factor(r["env"]) == "earth"}
    out = []
    for r in records:
        f = factor(r["env"])
        base = earth.get(r["unit"])
        if f == "earth" or base is None:
            continue
        g0 = _along(base["gen"], r["env"])
        dgen = {k: r["gen"][k] - g0[k] for k in r["gen"]}
        dsim = None
        if r.get("sim") is not None and base.get("sim") is not None:
            s0 = _along(base["sim"], r["env"])
            dsim = {k: r["sim"][k] - s0[k] for k in r["sim"]}
        out.append({"unit": r["unit"], "env": [float(v) for v in r["env"]], "factor": f, "dgen": dgen, "dsim": dsim})
    return out


def _along(q: dict[str, float], env: Sequence[float]) -> dict[str, float]:
    """``q`` with drift_along_wind_m recomputed along ``env``'s wind (the Earth record has no wind)."""
    _, wx, wy = (float(v) for v in env)
    w = np.array([wx, wy])
    norm = float(np.linalg.norm(w))
    along = float(np.array([q["drift_x_m"], q["drift_z_m"]]) @ w / norm) if norm > 0 else 0.0
    return {**q, "drift_along_wind_m": along}


def sign_agreement(pairs: Sequence[tuple[float, float]], tolerance: float) -> float:
    """Fraction of (Δg, Δs) with |Δs| > tolerance whose signs agree (NaN when none qualifies)."""
    use = [(g, s) for g, s in pairs if abs(s) > tolerance]
    if not use:
        return float("nan")
    return float(np.mean([np.sign(g) == np.sign(s) for g, s in use]))


def slope_ratio(pairs: Sequence[tuple[float, float]]) -> float:
    """Through-origin least-squares slope of Δg on Δs (NaN when Σ Δs² = 0)."""
    if not pairs:
        return float("nan")
    g, s = np.asarray(pairs, dtype=np.float64).T
    den = float(s @ s)
    return float(g @ s / den) if den > 0 else float("nan")


def _effect_slope(pairs: Sequence[tuple[float, float]], tolerance: float) -> float:
    """:func:`slope_ratio` when some |Δs| exceeds ``tolerance``, else NaN."""
    return slope_ratio(pairs) if any(abs(s) > tolerance for _, s in pairs) else float("nan")


def score(effs: Sequence[dict[str, Any]], *, resamples: int = 1000, seed: int = 0) -> list[dict[str, Any]]:
    """Sign agreement and slope ratio per (factor, quantity), bootstrap intervals over units.

    Returns:
        rows {factor, quantity, n_pairs, n_units, n_effect (|Δs| > tolerance), sign_agreement [est, lo, hi],
        slope_ratio [est, lo, hi], mean_dgen, mean_dsim}.
    """
    rows = []
    for f in ("gravity", "wind", "combo"):
        mine = [e for e in effs if e["factor"] == f and e["dsim"] is not None]
        for q in QUANTITIES[f]:
            by_unit: dict[Any, list[tuple[float, float]]] = {}
            for e in mine:
                by_unit.setdefault(e["unit"], []).append((e["dgen"][q], e["dsim"][q]))
            if not by_unit:
                continue
            units = list(by_unit.values())
            tol = TOLERANCE[q]
            flat = [p for u in units for p in u]
            sign = bootstrap_interval(units, lambda us: sign_agreement([p for u in us for p in u], tol),
                                      resamples=resamples, seed=seed)
            slope = bootstrap_interval(units, lambda us: _effect_slope([p for u in us for p in u], tol),
                                       resamples=resamples, seed=seed)
            rows.append({"factor": f, "quantity": q, "n_pairs": len(flat), "n_units": len(units),
                         "n_effect": sum(abs(s) > tol for _, s in flat), "sign_agreement": list(sign),
                         "slope_ratio": list(slope), "mean_dgen": float(np.mean([g for g, _ in flat])),
                         "mean_dsim": float(np.mean([s for _, s in flat]))})
    return rows


def additivity(effs: Sequence[dict[str, Any]], *, resamples: int = 1000, seed: int = 0) -> list[dict[str, Any]]:
    """Additivity error of each combination φ against its single-factor parts, generated and simulated.

    For φ = (g, w_x, w_y) the parts are (g, 0, 0), (−9.81, w_x, 0) and (−9.81, 0, w_y) (those present
    in the grid; a part with no change, e.g. w_y = 0, contributes nothing). Per quantity: mean over
    units of |Δ(φ) − Σ Δ(parts)| with a bootstrap interval; ``sim`` only over units whose rollouts tracked.
    """
    index = {(e["unit"], tuple(e["env"])): e for e in effs}
    rows = []
    for combo_env in dict.fromkeys(tuple(e["env"]) for e in effs if e["factor"] == "combo"):
        g, wx, wy = combo_env
        parts = [p for p in ((g, 0.0, 0.0), (EARTH[0], wx, 0.0), (EARTH[0], 0.0, wy)) if factor(p) != "earth"]
        for q in ("apex_m", "flight_s", "step_length_m", "drift_x_m", "drift_z_m"):
            out: dict[str, Any] = {"env": list(combo_env), "quantity": q}
            for which in ("dgen", "dsim"):
                errs = []
                for e in effs:
                    if tuple(e["env"]) != combo_env or e[which] is None:
                        continue
                    found = [index.get((e["unit"], p)) for p in parts]
                    if any(x is None or x[which] is None for x in found):
                        continue
                    errs.append(abs(e[which][q] - sum(x[which][q] for x in found)))  # type: ignore[index]
                key = "generated" if which == "dgen" else "simulated"
                out[key] = list(bootstrap_interval(errs, lambda v: float(np.mean(v)), resamples=resamples, seed=seed)) \
                    if errs else None
                out[f"n_{key}"] = len(errs)
            rows.append(out)
    return rows


def check_grid(envs: Sequence[Sequence[float]]) -> None:
    """The grid must hold Earth and at least one other φ."""
    kinds = [factor(e) for e in envs]
    if "earth" not in kinds or len(kinds) < 2:
        raise SimdiffError("the environment-response grid needs Earth (-9.81, 0, 0) and at least one other φ")
