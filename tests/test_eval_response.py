"""Environment-response measures on synthetic motions with known apex, flight time and drift."""

from __future__ import annotations

import numpy as np
import pytest

from simdiff.errors import SimdiffError
from simdiff.eval.response import (additivity, check_grid, effects, factor, quantities, score, sign_agreement,
                                   slope_ratio)
from simdiff.motion.synthetic import jump, walk

EARTH = (-9.81, 0.0, 0.0)


def drifting(frames: int, velocity: tuple[float, float]) -> np.ndarray:
    """A person standing still whose whole body drifts at a constant horizontal velocity (m/s along x, z)."""
    base = walk(frames, speed=0.0, amplitude=0.0, bounce=0.0).astype(np.float64)
    t = np.arange(frames)[:, None] / 20.0
    base[..., 0] += velocity[0] * t
    base[..., 2] += velocity[1] * t
    return base.astype(np.float32)


def test_quantities_of_a_ballistic_arc() -> None:
    still = quantities(jump(80, height=0.0, start=20), EARTH)
    arc = quantities(jump(80, height=0.4, start=20, airtime=0.8), EARTH)
    assert arc["apex_m"] - still["apex_m"] == pytest.approx(0.4, abs=0.01)  # apex of 4h·s(1−s) at s = 1/2
    assert arc["flight_s"] == pytest.approx(0.8, abs=0.1) and still["flight_s"] == 0.0
    low = quantities(jump(80, height=0.4, start=20, airtime=1.6), EARTH)
    assert low["flight_s"] - arc["flight_s"] == pytest.approx(0.8, abs=0.1)


def test_quantities_of_a_constant_velocity_drift() -> None:
    q = quantities(drifting(41, (0.5, -0.25)), (-9.81, 5.0, 0.0))  # 2 s
    assert q["drift_x_m"] == pytest.approx(1.0, abs=1e-4) and q["drift_z_m"] == pytest.approx(-0.5, abs=1e-4)
    assert q["drift_along_wind_m"] == pytest.approx(1.0, abs=1e-4)
    q = quantities(drifting(41, (0.5, -0.25)), (-9.81, 0.0, -3.0))
    assert q["drift_along_wind_m"] == pytest.approx(0.5, abs=1e-4)  # along −z
    assert quantities(drifting(41, (0.5, 0.0)), EARTH)["drift_along_wind_m"] == 0.0


def test_factor_and_grid() -> None:
    assert [factor(e) for e in (EARTH, (-3, 0, 0), (-9.81, 5, 0), (-3, 0, 7))] == ["earth", "gravity", "wind", "combo"]
    check_grid([EARTH, (-3.0, 0.0, 0.0)])
    with pytest.raises(SimdiffError, match="Earth"):
        check_grid([(-3.0, 0.0, 0.0), (-9.81, 5.0, 0.0)])


def _records(gen_gain: float, gen_drift: float, units: int = 4, broken_unit: int | None = None) -> list[dict]:
    """Units with a jump and a drift; the simulator's answer: apex +0.2 m at g = −3, drift +0.4 m at w_x = 5 N.

    The model's answer: ``gen_gain`` × the simulator's apex change and ``gen_drift`` m of drift.
    """
    recs = []
    for u in range(units):
        h = 0.2 + 0.05 * u
        earth = jump(80, height=h, start=20)
        still = drifting(80, (0.0, 0.0))
        sim_ok = u != broken_unit
        cases = {
            EARTH: (earth, earth),
            (-3.0, 0.0, 0.0): (jump(80, height=h + 0.2 * gen_gain, start=20), jump(80, height=h + 0.2, start=20)),
            (-9.81, 5.0, 0.0): (drifting(80, (gen_drift / (79 / 20), 0.0)), drifting(80, (0.4 / (79 / 20), 0.0))),
        }
        for env, (gen, sim) in cases.items():
            recs.append({"unit": (u, env == (-9.81, 5.0, 0.0)), "env": env, "gen": quantities(gen, env),
                         "sim": quantities(sim, env) if sim_ok or env == EARTH else None})
        recs.append({"unit": (u, True), "env": EARTH, "gen": quantities(still, EARTH), "sim": quantities(still, EARTH)})
    # every unit is (u, windy?): Earth record of the jump unit and of the drift unit
    return [r for r in recs if not (r["unit"][1] and r["env"] == (-3.0, 0.0, 0.0)) and
            not (not r["unit"][1] and r["env"] == (-9.81, 5.0, 0.0))]


def _row(rows: list[dict], f: str, q: str) -> dict:
    return next(r for r in rows if r["factor"] == f and r["quantity"] == q)


def test_score_slope_ratio_and_sign_agreement() -> None:
    rows = score(effects(_records(gen_gain=0.5, gen_drift=0.4)), resamples=200)
    apex = _row(rows, "gravity", "apex_m")
    assert apex["n_units"] == 4 and apex["n_effect"] == 4
    assert apex["sign_agreement"][0] == 1.0
    assert apex["slope_ratio"][0] == pytest.approx(0.5, abs=0.05)  # half the physical apex change
    drift = _row(rows, "wind", "drift_along_wind_m")
    assert drift["slope_ratio"][0] == pytest.approx(1.0, abs=1e-3) and drift["sign_agreement"][0] == 1.0
    lo, hi = drift["slope_ratio"][1:]
    assert lo <= 1.0 + 1e-9 and hi >= 1.0 - 1e-9


def test_an_env_blind_model_scores_no_response() -> None:
    rows = score(effects(_records(gen_gain=0.0, gen_drift=0.0)), resamples=100)
    assert _row(rows, "gravity", "apex_m")["slope_ratio"][0] == pytest.approx(0.0, abs=1e-6)
    assert _row(rows, "gravity", "apex_m")["sign_agreement"][0] == 0.0
    assert _row(rows, "wind", "drift_along_wind_m")["slope_ratio"][0] == pytest.approx(0.0, abs=1e-6)
    reverse = score(effects(_records(gen_gain=-1.0, gen_drift=-0.4)), resamples=100)
    assert _row(reverse, "wind", "drift_along_wind_m")["slope_ratio"][0] == pytest.approx(-1.0, abs=1e-3)


def test_failed_rollouts_are_left_out() -> None:
    effs = effects(_records(gen_gain=1.0, gen_drift=0.4, broken_unit=1))
    rows = score(effs, resamples=50)
    assert _row(rows, "gravity", "apex_m")["n_units"] == 3 and _row(rows, "wind", "drift_along_wind_m")["n_units"] == 3


def test_slope_and_sign_helpers() -> None:
    assert slope_ratio([(1.0, 2.0), (2.0, 4.0)]) == pytest.approx(0.5)
    assert np.isnan(slope_ratio([(1.0, 0.0)])) and np.isnan(slope_ratio([]))
    assert sign_agreement([(1.0, 0.5), (-1.0, 0.5), (3.0, 0.001)], 0.01) == 0.5  # the tiny effect is not counted
    assert np.isnan(sign_agreement([(1.0, 0.0)], 0.01))


def test_additivity_of_a_combination() -> None:
    """φ = (−3, 5, 0): gravity part raises the apex 0.2 m, the wind part 0; the combination raises it 0.3 m."""
    def rec(unit: int, env: tuple, apex: float, drift: float, sim_apex: float) -> dict:
        q = {"apex_m": apex, "flight_s": 0.0, "step_length_m": 0.0, "drift_x_m": drift, "drift_z_m": 0.0,
             "drift_along_wind_m": 0.0}
        s = {**q, "apex_m": sim_apex}
        return {"unit": unit, "env": env, "gen": q, "sim": s}

    recs = []
    for u in range(3):
        recs += [rec(u, EARTH, 1.0, 0.0, 1.0), rec(u, (-3.0, 0.0, 0.0), 1.2, 0.0, 1.2),
                 rec(u, (-9.81, 5.0, 0.0), 1.0, 0.4, 1.0), rec(u, (-3.0, 5.0, 0.0), 1.3, 0.4, 1.2)]
    rows = additivity(effects(recs), resamples=50)
    apex = next(r for r in rows if r["quantity"] == "apex_m")
    assert apex["env"] == [-3.0, 5.0, 0.0] and apex["n_generated"] == 3
    assert apex["generated"][0] == pytest.approx(0.1) and apex["simulated"][0] == pytest.approx(0.0)
    drift = next(r for r in rows if r["quantity"] == "drift_x_m")
    assert drift["generated"][0] == pytest.approx(0.0)
