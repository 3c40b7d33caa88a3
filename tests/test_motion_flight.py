"""The one offline flight rule (simdiff.motion.flight) on motions the tests make."""

from __future__ import annotations

import numpy as np
import pytest

from simdiff.errors import SimdiffError
from simdiff.motion.flight import FEET, LIFT, airborne, flight_stats, flights, runs


def _standing(T: int = 60) -> np.ndarray:
    """(T, 22, 3) a still body: toes on the floor, ankles 8 cm up, the rest above."""
    j = np.zeros((T, 22, 3), dtype=np.float32)
    j[..., 1] = np.linspace(0.1, 1.6, 22)
    j[:, [7, 8], 1] = 0.08
    j[:, [10, 11], 1] = 0.0
    return j


def _jump(j: np.ndarray, start: int, frames: int, apex: float, fps: float = 20.0) -> np.ndarray:
    """Adds a parabolic flight of ``frames`` frames peaking ``apex`` m above stance."""
    out = j.copy()
    t = (np.arange(frames + 2) / (frames + 1))
    out[start - 1:start + frames + 1, :, 1] += (4 * apex * t * (1 - t))[:, None]
    return out


def test_runs_are_half_open() -> None:
    assert runs(np.array([0, 1, 1, 0, 1], dtype=bool)) == [(1, 3), (4, 5)]
    assert runs(np.zeros(3, dtype=bool)) == []


def test_a_parabolic_jump_is_one_flight_with_its_apex_gain() -> None:
    j = _jump(_standing(), 20, 8, 0.4)
    found = flights(j)
    assert len(found) == 1
    s, e = found[0]
    # every frame of the parabola but the ones within 1 cm of stance is airborne
    lifted = j[:, FEET, 1].min(axis=1) - _standing()[:, FEET, 1].min(axis=1)
    assert np.array_equal(np.flatnonzero(airborne(j)), np.flatnonzero(lifted > 0.01))
    stats = flight_stats(j)
    assert stats["flights"] == 1 and stats["flight_s"] == pytest.approx((e - s) / 20.0)
    assert stats["flight_total_s"] == stats["flight_s"]
    assert stats["apex_gain_m"] == pytest.approx(float(j[s:e, 0, 1].max() - j[s - 1, 0, 1]))
    assert 0.3 < stats["apex_gain_m"] <= 0.4


def test_ground_offset_and_small_lifts_do_not_change_flights() -> None:
    j = _jump(_standing(), 20, 8, 0.4)
    up = j.copy()
    up[..., 1] += 0.7
    assert flights(up) == flights(j)
    assert flight_stats(up) == pytest.approx(flight_stats(j), abs=1e-6)
    shuffle = _standing()
    shuffle[10:20, FEET, 1] += LIFT * 0.8  # feet up, but less than LIFT: no flight
    assert flights(shuffle) == []


def test_a_motion_that_starts_in_the_air_has_no_take_off() -> None:
    j = _standing()
    j[:5, :, 1] += 0.3
    assert flights(j) == []


def test_bad_shape_is_one_line_error() -> None:
    with pytest.raises(SimdiffError, match=r"\(1, 22, 3\)"):
        flights(np.zeros((1, 22, 3)))
    with pytest.raises(SimdiffError, match="shape"):
        flight_stats(np.zeros((10, 24, 3)))
