"""Physics-response figures (models with a Sim Encoder): g = −1.6 vs −9.81 on jumps, ±10 N wind on walks.

Every sample is generated under Earth and under φ with the same noise (:mod:`.samples`). The
simulator's answer for that motion, as in the environment-response benchmark
(:mod:`simdiff.eval.experiments.env_response`): the *Earth* sample re-tracked under φ minus the same
sample re-tracked under Earth, flights following gravity (the projector's flight clock); pairs
where either rollout fell have no simulated effect. Effects come from
:func:`simdiff.eval.response.effects`, slope ratios and sign agreement from
:func:`simdiff.eval.response.score` (bootstrap over samples).

* Gravity: a sample *rises* when both its apex gain (pelvis over take-off in the longest flight)
  and its longest flight time are larger at −1.6 than at Earth, and its −1.6 motion touches the
  floor (:func:`simdiff.motion.metrics.never_touches`: a sample hovering above 0.10 m all clip long
  has "flights" by the relative flight rule but never takes off; session 50's runs did). Ratio per
  sample: generated change ÷ simulated change, over samples that touch the floor and whose simulated
  change exceeds the response tolerance; the check takes the median per quantity (with a 95 % percentile
  bootstrap interval over those samples, ``ci95``, since session 52). The counts of
  samples that never touch the floor are reported for Earth, −1.6 and the simulator's −1.6 rollouts.
  A sample that *glides* (:func:`simdiff.motion.metrics.glides`: the body travels while no foot joint ever
  lifts) does not rise either and is left out of the ratios (session 52's runs at environment guidance 4).
  The same function runs on the run prompts (``gravity_runs``, no verdict): session 50's environment
  guidance 4 raised the jumps as the simulator does but lifted whole runs off the floor; the
  never-touch counts and the change of time in flight against the simulator's show that.
* Wind: a (sample, φ) pair drifts *downwind* when its root displacement along the wind grows
  against Earth (Δ > 0). The drift per 10 N is that Δ (|w| = 10 N), generated and simulated.
  Samples that never touch the floor, and those that glide, are counted per φ.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from simdiff.eval.model_check.detect import quartiles, wilson
from simdiff.eval.response import TOLERANCE, effects, quantities, score
from simdiff.eval.stats import bootstrap_interval
from simdiff.motion.flight import flight_stats
from simdiff.motion.metrics import FLOOR_CLEARANCE, GLIDE_LIFT, GLIDE_SPEED, glides, never_touches

GLIDE_TEXT: str = (f"pelvis faster than {GLIDE_SPEED} m/s while no foot joint's height changes by {GLIDE_LIFT} m; "
                   "such a sample never rises")

GRAVITY_QUANTITIES: dict[str, float] = {"apex_gain_m": TOLERANCE["apex_m"], "flight_s": TOLERANCE["flight_s"]}
"""Quantities of the gravity check with the |simulated change| a ratio needs."""


def motion_quantities(joints: np.ndarray, env: Sequence[float]) -> dict[str, float]:
    """:func:`simdiff.eval.response.quantities` plus ``apex_gain_m`` and ``flight_total_s`` (all flights, s;
    :func:`simdiff.motion.flight.flight_stats`)."""
    stats = flight_stats(joints)
    return {**quantities(joints, env), "apex_gain_m": stats["apex_gain_m"], "flight_total_s": stats["flight_total_s"]}


def simulate(projector: Any, earth: np.ndarray, envs: Sequence[Sequence[float]]) -> tuple[dict, dict[str, int], list[str]]:
    """Re-track every Earth sample under every φ; ({(i, φ): quantities | None}, statuses, first errors).

    Tracked rollouts' quantities carry ``never_touch`` (1.0 / 0.0)."""
    from simdiff.sim.env import Environment

    jobs = [(i, tuple(float(v) for v in env)) for env in envs for i in range(len(earth))]
    results = projector([earth[i] for i, _ in jobs], [Environment(*env) for _, env in jobs])
    out: dict[tuple[int, tuple[float, ...]], dict[str, float] | None] = {}
    statuses: dict[str, int] = {}
    errors: list[str] = []
    for (i, env), (rollout, info) in zip(jobs, results):
        failed = isinstance(info, str)
        ok = not failed and bool(_get(info, "success")) and rollout is not None and len(rollout) >= 2
        status = "error" if failed else str(_get(info, "status", "ok" if ok else "fell"))
        statuses[status] = statuses.get(status, 0) + 1
        if failed and len(errors) < 3:
            errors.append(str(info))
        out[(i, env)] = ({**motion_quantities(np.asarray(rollout), env),
                          "never_touch": float(never_touches(np.asarray(rollout))[0])} if ok else None)
    return out, statuses, errors


def _get(info: Any, key: str, default: Any = None) -> Any:
    return info.get(key, default) if isinstance(info, dict) else getattr(info, key, default)


def _records(ids: Sequence[str], generated: dict[tuple[float, ...], np.ndarray], sims: dict) -> list[dict[str, Any]]:
    return [{"unit": u, "env": list(env), "gen": motion_quantities(joints[i], env), "sim": sims.get((i, env))}
            for env, joints in generated.items() for i, u in enumerate(ids)]


def gravity_response(ids: Sequence[str], earth: np.ndarray, low: np.ndarray, low_g: float, projector: Any, *,
                     resamples: int = 1000, seed: int = 0) -> dict[str, Any]:
    """Apex-gain and flight-time response of jump samples to g = ``low_g`` (same noise as ``earth``)."""
    e_env, l_env = (-9.81, 0.0, 0.0), (float(low_g), 0.0, 0.0)
    sims, statuses, errors = simulate(projector, earth, [e_env, l_env])
    effs = effects(_records(ids, {e_env: earth, l_env: low}, sims))
    floats = dict(zip(ids, never_touches(low)))
    glide = dict(zip(ids, glides(low)))
    grounded = [not floats[e["unit"]] and not glide[e["unit"]] for e in effs]
    rises = [e["dgen"]["apex_gain_m"] > 0 and e["dgen"]["flight_s"] > 0 and ok for e, ok in zip(effs, grounded)]
    frac, lo, hi = wilson(sum(rises), len(rises))
    ratios: dict[str, Any] = {}
    for q, tol in GRAVITY_QUANTITIES.items():
        pairs = [(e["dgen"][q], e["dsim"][q]) for e, ok in zip(effs, grounded) if e["dsim"] is not None and ok]
        use = [g / s for g, s in pairs if abs(s) > tol]
        ci = list(bootstrap_interval(use, np.median, resamples=resamples, seed=seed)[1:]) if use else [float("nan")] * 2
        ratios[q] = {"median_ratio": float(np.median(use)) if use else float("nan"), "ci95": ci, "n_ratio": len(use),
                     "n_tracked": len(pairs), "tolerance": tol,
                     "generated_change": quartiles([e["dgen"][q] for e in effs]),
                     "simulated_change": quartiles([s for _, s in pairs])}
    return {"env": list(l_env), "n": len(effs), "rise_both": sum(rises), "rise_fraction": frac, "wilson95": [lo, hi],
            "rise_apex_only": sum(e["dgen"]["apex_gain_m"] > 0 for e in effs),
            "rise_flight_only": sum(e["dgen"]["flight_s"] > 0 for e in effs),
            "never_touch": {"earth": int(never_touches(earth).sum()), "low_g": int(sum(floats.values())),
                            "simulated_low_g": int(sum(v["never_touch"] for (_, env), v in sims.items()
                                                       if env == l_env and v is not None)),
                            "simulated_tracked": sum(v is not None for (_, env), v in sims.items() if env == l_env),
                            "rule": f"lowest joint > {FLOOR_CLEARANCE:.2f} m above y = 0 in every frame; such a sample never rises"},
            "glides": {"earth": int(glides(earth).sum()), "low_g": int(sum(glide.values())), "rule": GLIDE_TEXT},
            "airborne_total_s": _airborne(effs, grounded),
            "ratios": ratios, "scores": score(effs, resamples=resamples, seed=seed), "rollouts": statuses,
            "rollout_errors": errors}


def _airborne(effs: list[dict[str, Any]], grounded: list[bool]) -> dict[str, Any]:
    """Change of the time spent in flight (all flights, s) at low g: generated and simulated quartiles, over the
    samples that touch the floor (the simulated change over those the simulator tracked)."""
    use = [e for e, ok in zip(effs, grounded) if ok]
    return {"generated_change": quartiles([e["dgen"]["flight_total_s"] for e in use]),
            "simulated_change": quartiles([e["dsim"]["flight_total_s"] for e in use if e["dsim"] is not None])}


def wind_response(ids: Sequence[str], earth: np.ndarray, windy: dict[tuple[float, ...], np.ndarray], projector: Any, *,
                  resamples: int = 1000, seed: int = 0) -> dict[str, Any]:
    """Drift along the wind of walk samples under each windy φ (same noise as ``earth``)."""
    e_env = (-9.81, 0.0, 0.0)
    envs = [tuple(float(v) for v in env) for env in windy]
    sims, statuses, errors = simulate(projector, earth, [e_env, *envs])
    by_env = {env: windy[key] for env, key in zip(envs, windy)}
    effs = effects(_records(ids, {e_env: earth, **by_env}, sims))
    along = [e["dgen"]["drift_along_wind_m"] for e in effs]
    sim_along = [e["dsim"]["drift_along_wind_m"] for e in effs if e["dsim"] is not None]
    frac, lo, hi = wilson(sum(d > 0 for d in along), len(along))
    per_env = {}
    for env in envs:
        g = [e["dgen"]["drift_along_wind_m"] for e in effs if tuple(e["env"]) == env]
        s = [e["dsim"]["drift_along_wind_m"] for e in effs if tuple(e["env"]) == env and e["dsim"] is not None]
        per_env[f"wx{env[1]:+g} wy{env[2]:+g}"] = {"downwind": sum(d > 0 for d in g), "n": len(g),
                                                   "never_touch": int(never_touches(by_env[env]).sum()),
                                                   "glides": int(glides(by_env[env]).sum()),
                                                   "generated_m": quartiles(g), "simulated_m": quartiles(s)}
    gen_q, sim_q = quartiles(along), quartiles(sim_along)
    return {"envs": [list(e) for e in envs], "n": len(along), "downwind": sum(d > 0 for d in along),
            "downwind_fraction": frac, "wilson95": [lo, hi],
            "drift_per_10n_generated_m": gen_q, "drift_per_10n_simulated_m": sim_q,
            "median_ratio_generated_to_simulated": gen_q["median"] / sim_q["median"] if sim_q["n"] and sim_q["median"]
            else float("nan"),
            "per_env": per_env, "scores": score(effs, resamples=resamples, seed=seed), "rollouts": statuses,
            "rollout_errors": errors}
