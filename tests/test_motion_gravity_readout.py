"""Gravity read back from flights: exact on ballistic flights, none without flight, COM of a standing body."""

from __future__ import annotations

import numpy as np
import pytest

from simdiff.errors import SimdiffError
from simdiff.motion.gravity_readout import MIN_FIT_FRAMES, centre_of_mass, fit_parabola, flight_fits, read_gravity
from simdiff.motion.synthetic import jump, walk


def standing(frames: int) -> np.ndarray:
    return walk(frames, speed=0.0, amplitude=0.0, bounce=0.0)


@pytest.mark.parametrize("gravity", [-1.6, -3.7, -9.81, -20.0])
def test_a_ballistic_jump_reads_its_gravity(gravity: float) -> None:
    height = 0.4
    airtime = float(np.sqrt(8 * height / -gravity))  # apex h = |g| a² / 8
    joints = jump(frames=int(airtime * 20) + 40, height=height, start=15, airtime=airtime)
    fits = flight_fits(joints)
    assert len(fits) == 1 and fits[0].end - fits[0].start >= MIN_FIT_FRAMES
    assert fits[0].gravity == pytest.approx(gravity, rel=1e-2)  # the synthetic body swings its arms a little
    assert fits[0].rmse_m < 1e-3 and 0.2 < fits[0].apex_m < height
    assert read_gravity(joints, point="pelvis")["gravity"] == pytest.approx(gravity, rel=1e-3)


def test_no_flight_no_reading_and_short_hops_are_skipped() -> None:
    assert read_gravity(standing(60)) is None
    hop = jump(frames=60, height=0.08, start=15, airtime=0.2)  # 4 frames up: too short to fit
    assert flight_fits(hop) == []


def test_parabola_fit_and_centre_of_mass() -> None:
    t = np.arange(10) / 20.0
    g, rmse, apex = fit_parabola(-4.0 / 2 * t**2 + 1.0 * t + 0.3)
    assert g == pytest.approx(-4.0) and rmse < 1e-9 and apex == pytest.approx(1.0**2 / (2 * 4.0))
    body = standing(3)
    com = centre_of_mass(body)
    assert com.shape == (3, 3) and body[0, :, 1].min() < com[0, 1] < body[0, 15, 1]  # between the feet and the head
    assert abs(com[0, 1] - body[0, 0, 1]) < 0.2  # near the pelvis for a standing body
    with pytest.raises(SimdiffError, match="point must be"):
        flight_fits(body, point="knee")
