"""simdiff.motion.ballistic: flights rise and fall with the gravity they are under."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from simdiff.errors import SimdiffError
from simdiff.motion.ballistic import VEL_Y, ballistic_flights, foot_clearance, parabola_shift
from simdiff.motion.features import features_to_joints, joints_to_features
from simdiff.motion.flight import flight_stats, flights
from simdiff.motion.synthetic import jump


def _features(joints: np.ndarray) -> torch.Tensor:
    return torch.from_numpy(joints_to_features(joints)).double()


def _pelvis(f: torch.Tensor) -> np.ndarray:
    return features_to_joints(f).numpy()[..., 0, 1]


def test_a_ballistic_jump_under_its_own_gravity_is_left_as_it_is() -> None:
    # synthetic jump: 0.4 m over 0.5 s of air is a parabola of g = 8 h / D² = 12.8 m/s²
    f = _features(jump(60, height=0.4, start=20, airtime=0.5))
    out = ballistic_flights(f, -12.8)
    assert torch.allclose(out, f, atol=1e-5)


def test_weaker_gravity_raises_the_flight_by_g_d2_over_8() -> None:
    joints = jump(60, height=0.4, start=20, airtime=0.5)
    f = _features(joints)
    spans = flights(features_to_joints(f).numpy())
    assert spans == [(21, 30)]  # take-off frame 20, landing frame 30: D = 0.5 s
    out = ballistic_flights(f, -1.6)
    before, after = _pelvis(f), _pelvis(out)
    assert after[25] - after[20] == pytest.approx(1.6 * 0.5 ** 2 / 8, abs=1e-5)  # mid-flight over the chord
    assert np.allclose(after[:21], before[:21], atol=1e-6) and np.allclose(after[30:], before[30:], atol=1e-6)
    # the whole body moves with the pelvis: poses and the horizontal path are unchanged
    jb, ja = features_to_joints(f).numpy(), features_to_joints(out).numpy()
    assert np.allclose(ja[..., 1] - ja[:, :1, 1], jb[..., 1] - jb[:, :1, 1], atol=1e-6)
    assert np.allclose(ja[..., [0, 2]], jb[..., [0, 2]], atol=1e-6)


def test_a_hovering_flight_is_lifted_into_a_parabola_and_velocities_follow() -> None:
    joints = jump(80, height=0.0, start=20).astype(np.float64)
    joints[21:61, :, 1] += 0.2  # 2 s flat hover 0.2 m up: no gravity does that
    f = _features(joints.astype(np.float32))
    out = ballistic_flights(f, -1.6)
    y = _pelvis(out)
    d = 41 * 0.05  # take-off frame 20, landing frame 61
    tau = (np.arange(20, 62) - 20) * 0.05
    assert np.allclose(y[20:62] - y[20], 0.5 * 1.6 * tau * (d - tau), atol=1e-5)
    # the vertical joint velocities say the same as the positions
    j = features_to_joints(out).numpy()
    assert np.allclose(out[:-1, VEL_Y].numpy(), j[1:, :, 1] - j[:-1, :, 1], atol=1e-5)
    assert flight_stats(j)["flight_s"] == flight_stats(features_to_joints(f).numpy())["flight_s"]  # timing kept
    half = ballistic_flights(f, -1.6, strength=0.5)
    assert np.allclose(_pelvis(half) - _pelvis(f), 0.5 * (y - _pelvis(f)), atol=1e-6)
    assert torch.equal(ballistic_flights(f, -1.6, strength=0.0), f)


def test_batches_take_one_gravity_per_clip_and_keep_padding_and_open_flights() -> None:
    a = _features(jump(60, height=0.4, start=20, airtime=0.5))
    b = _features(jump(60, height=0.4, start=45, airtime=1.0))  # still in the air at the end: no landing
    batch = torch.stack([a, b]).float()
    out = ballistic_flights(batch, torch.tensor([-12.8, -1.6]), lengths=torch.tensor([60, 55]))
    assert out.dtype == torch.float32 and out.shape == batch.shape
    assert torch.allclose(out[0], batch[0], atol=1e-5)
    # no landing inside its 55 frames: an already ballistic open flight is kept; under g -1.6 it becomes a parabola
    # of that curvature from its take-off
    c = _features(jump(60, height=0.4, start=48, airtime=0.5))[None]  # 12.8 m/s², in the air past frame 54
    kept = ballistic_flights(c, -12.8, lengths=torch.tensor([55]))
    assert torch.allclose(kept, c, atol=1e-5)
    low = _pelvis(ballistic_flights(c, -1.6, lengths=torch.tensor([55]))[0, :55])
    assert np.allclose(np.diff(low[48:55], 2), -1.6 * 0.05 ** 2, atol=1e-6)
    assert np.allclose(low[:49], _pelvis(c[0, :49]), atol=1e-6)
    single = ballistic_flights(a, [-1.6])
    assert single.shape == a.shape


def test_parabola_shift_skips_spans_without_take_off_or_landing() -> None:
    h = np.zeros(10)
    assert np.array_equal(parabola_shift(h, [(0, 4)], -9.81), np.zeros(10))
    up = parabola_shift(h, [(6, 10)], -9.81)  # a flat hover to the end: it has not landed, so it is back at the
    assert up[:5].tolist() == [0.0] * 5 and up[9] == pytest.approx(0.0)  # take-off height no sooner than the end
    assert up[7] == pytest.approx(0.5 * 9.81 * 0.2 * 0.1 - 0.5 * 9.81 * 0.1 ** 2)  # v0 = g·D/2, D 0.2 s
    d = parabola_shift(h, [(3, 6)], -9.81)  # take-off 2, landing 6: 0.2 s
    assert d[2] == 0 and d[6] == 0 and d[4] == pytest.approx(9.81 * 0.2 ** 2 / 8)


@pytest.mark.parametrize("kwargs, message", [
    ({"gravity": float("nan")}, "finite gravity, got nan"),
    ({"gravity": float("inf")}, "finite gravity, got inf"),
    ({"gravity": [-9.81, -1.6, -3.7]}, "1 or 1 gravity values, got 3"),
    ({"gravity": -9.81, "strength": 1.5}, "ballistic strength must be in [0, 1], got 1.5"),
])
def test_bad_input_gets_one_clear_line(kwargs: dict, message: str) -> None:
    f = _features(jump(30))[None]
    with pytest.raises(SimdiffError, match=message.replace("[", r"\[").replace("]", r"\]")):
        ballistic_flights(f, **kwargs)
    with pytest.raises(SimdiffError, match="needs \\(B, T >= 2, 263\\)"):
        ballistic_flights(torch.zeros(4, 10), -9.81)


def test_a_flight_too_high_for_its_duration_stops_on_the_floor_not_under_it() -> None:
    # 0.75 m up in 1 s: under g -1.6 the parabola rises 0.2 m, so the pelvis would be pulled about 0.55 m down; with
    # the legs hanging so that the feet are 8 cm over the floor mid-flight, they would go through it
    f = _features(jump(60, height=0.75, start=20, airtime=1.0))
    feet = [4 + 3 * (k - 1) + 1 for k in (7, 10, 8, 11)]  # the feet's "ric" heights (absolute in HumanML3D)
    f[27:34, feet] = 0.08 + f[27:34, feet] - f[27:34, feet].amin(dim=1, keepdim=True)
    before = features_to_joints(f).numpy()
    assert flights(before) == [(21, 40)]
    floor = np.percentile(before[:, (7, 10, 8, 11), 1], 5, axis=0)
    free = parabola_shift(before[:, 0, 1], flights(before), -1.6)  # without a floor: feet under it
    assert (before[:, (7, 10, 8, 11), 1] + free[:, None] < floor - 0.3).any()
    j = features_to_joints(ballistic_flights(f, -1.6)).numpy()
    assert (j[:, (7, 10, 8, 11), 1] >= floor - 1e-5).all()  # nothing below its own ground
    assert (j[:, 0, 1] <= before[:, 0, 1] + 1e-6).all()  # only ever moved down in this flight
    assert j[25, 0, 1] < before[25, 0, 1] - 0.1  # where the feet had room, down to the parabola
    assert j[25, 0, 1] == pytest.approx(before[20, 0, 1] + 0.5 * 1.6 * 0.25 * 0.75, abs=1e-5)
    assert np.isclose(j[30, (7, 10, 8, 11), 1] - floor, 0.0, atol=1e-5).any()  # where they had not, on the floor
    assert np.allclose(foot_clearance(before), (before[:, (7, 10, 8, 11), 1] - floor).min(axis=1))
    assert foot_clearance(before)[20] < 0.05 < foot_clearance(before)[30] < 0.09  # on the ground / hanging legs
