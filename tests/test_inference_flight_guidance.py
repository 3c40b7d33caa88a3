"""Flight guidance: flights of x̂₀ bent onto parabolas of the requested gravity during denoising."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from simdiff.diffusion.config import SamplingConfig
from simdiff.errors import SimdiffError
from simdiff.inference.flight_guidance import FlightGuide, flight_correction, with_flight_guidance
from simdiff.motion.features import features_to_joints, joints_to_features
from simdiff.motion.gravity_readout import read_gravity
from simdiff.motion.synthetic import jump, walk

pytestmark = pytest.mark.usefixtures("one_torch_thread")


@pytest.fixture(scope="module")
def tiny_generator_sim():
    from simdiff.train.testing import tiny_generator

    return tiny_generator()


def earth_jump(frames: int = 80) -> np.ndarray:
    """(T, 22, 3) a 0.4 m jump whose flight is a parabola of −9.81 m/s²."""
    return jump(frames=frames, height=0.4, start=20, airtime=float(np.sqrt(8 * 0.4 / 9.81)))


def raised(joints: np.ndarray, move: np.ndarray) -> np.ndarray:
    out = joints.astype(np.float64).copy()
    out[..., 1] += move[:, None]
    return out


@pytest.mark.parametrize("gravity", [-1.6, -3.7, -9.81, -20.0])
def test_the_correction_puts_the_flight_on_a_parabola_of_the_gravity(gravity: float) -> None:
    joints = earth_jump()
    before = read_gravity(joints)
    assert before is not None and abs(before["gravity"] / -9.81 - 1) < 0.05
    moved = joints.astype(np.float64)
    for _ in range(3):  # FlightGuide's passes: the moved flight's frames can differ from the first decoding's
        moved = raised(moved, flight_correction(moved, gravity))
    after = read_gravity(moved)
    assert after is not None and abs(after["gravity"] / gravity - 1) < 0.03 and after["rmse_m"] < 0.005
    moved = raised(moved, flight_correction(moved, gravity))  # a short flight bent far converges a pass later
    after = read_gravity(moved)
    assert after is not None
    assert after["gravity"] == pytest.approx(gravity, rel=1e-3)
    assert after["rmse_m"] < 1e-3
    move = moved[:, 0, 1] - joints[:, 0, 1]
    # take-off and landing kept: nothing moves far from the flight, and nothing jumps at its edges
    assert np.all(move[:10] == 0) and np.all(move[-10:] == 0)
    # the stance is never lifted, so a flight bent far takes off with a step: bounded by a take-off speed
    assert np.abs(np.diff(moved[:, 0, 1])).max() * 20.0 < 6.0


def test_a_motion_without_a_readable_flight_is_left_exactly_as_it_is() -> None:
    assert not flight_correction(walk(60).astype(np.float64), -1.6).any()
    feats = torch.as_tensor(joints_to_features(walk(60)))[None]
    guide = FlightGuide([-1.6], torch.zeros(263), torch.ones(263), passes=3)
    assert torch.equal(guide(feats, 0, feats), feats)


def jump_features() -> torch.Tensor:
    return torch.as_tensor(joints_to_features(earth_jump()), dtype=torch.float32)


def test_the_guide_works_on_normalised_features_per_row_and_only_at_or_below_max_t() -> None:
    feats = jump_features()
    mean, std = feats.mean(0), feats.std(0) + 0.1
    x0 = ((torch.stack([feats, feats]) - mean) / std)
    guide = FlightGuide([-1.6, -9.81], mean, std, passes=3, max_t=950)
    out = guide(x0, 900, x0)
    joints = features_to_joints((out * std + mean).double()).numpy()
    moon, earth = read_gravity(joints[0]), read_gravity(joints[1])
    assert moon is not None and abs(moon["gravity"] / -1.6 - 1) < 0.03 and moon["rmse_m"] < 0.01
    assert earth is not None and abs(earth["gravity"] / -9.81 - 1) < 0.05
    assert torch.equal(guide(x0, 951, x0), x0)
    assert torch.equal(FlightGuide([-1.6, -1.6], mean, std, passes=0)(x0, 0, x0), x0)


def test_with_flight_guidance_runs_the_given_hook_at_its_timesteps_then_the_guide() -> None:
    feats = jump_features()
    mean, std = torch.zeros(263), torch.ones(263)
    seen: list[int] = []

    def hook(x0: torch.Tensor, t: int, x_t: torch.Tensor) -> torch.Tensor:
        seen.append(t)
        return feats[None].clone()

    config = SamplingConfig(flight_passes=3, edit_t=950)
    combined = with_flight_guidance(hook, [500], config, [-3.7], mean, std, [feats.shape[0]])
    x = torch.zeros_like(feats)[None]
    assert torch.equal(combined(x, 999, x), x) and seen == []  # above edit_t and not a hook step
    out = combined(x, 500, x)
    assert seen == [500]
    reading = read_gravity(features_to_joints(out[0].double()).numpy())
    assert reading is not None and abs(reading["gravity"] / -3.7 - 1) < 0.02


def test_generate_bends_the_flights_of_its_samples(tiny_generator_sim) -> None:
    gen = tiny_generator_sim
    target = ((jump_features() - gen.mean) / gen.std)[None]

    def always_the_jump(x0: torch.Tensor, t: int, x_t: torch.Tensor) -> torch.Tensor:
        return target.expand_as(x0).clone()

    frames = target.shape[1]
    readings = {}
    for passes in (0, 3):
        config = SamplingConfig(steps=4, guidance=1.0, flight_passes=passes)
        out = gen.generate(["a jump"], frames, config, env=[-1.6, 0.0, 0.0], seed=0, x0_hook=always_the_jump)
        readings[passes] = read_gravity(features_to_joints(out.features[0].double()).numpy())
    assert readings[0] is not None and abs(readings[0]["gravity"] / -9.81 - 1) < 0.05
    assert readings[3] is not None and abs(readings[3]["gravity"] / -1.6 - 1) < 0.03


@pytest.mark.parametrize("value", [-1, 11, 1.5, True])
def test_bad_pass_counts_are_one_line(value: object) -> None:
    with pytest.raises(SimdiffError, match="flight-passes"):
        SamplingConfig(flight_passes=value)  # type: ignore[arg-type]


def test_sampling_json_takes_the_pass_count() -> None:
    assert SamplingConfig.from_dict({"flight_passes": 3}).flight_passes == 3


@pytest.mark.parametrize("gravity", [-1.6, -20.0])
def test_no_foot_is_pushed_below_the_floor_and_no_flight_is_made_up(gravity: float) -> None:
    from simdiff.motion.flight import flights, heights_over_ground

    joints = earth_jump().astype(np.float64)
    moved = joints
    for _ in range(3):
        moved = raised(moved, flight_correction(moved, gravity))
    (s0, e0), = flights(joints)
    (s1, e1), = flights(moved)
    assert s1 >= s0 - 3 and e1 <= e0 + 1  # the network's flight keeps its frames (edges within 5 cm may join)
    lowest = heights_over_ground(moved).min(axis=1)
    assert lowest.min() >= min(heights_over_ground(joints).min(), 0.0) - 1e-9


def test_two_hops_keep_their_landing_and_each_its_own_parabola() -> None:
    from simdiff.motion.flight import flights

    airtime = float(np.sqrt(8 * 0.4 / 9.81))
    hops = jump(frames=90, height=0.4, start=20, airtime=airtime).astype(np.float64)
    hops[..., 1] += jump(frames=90, height=0.4, start=34, airtime=airtime)[..., 1] - jump(frames=90, height=0.0)[..., 1]
    moved = hops
    for _ in range(3):
        moved = raised(moved, flight_correction(moved, -3.7))
    assert len(flights(moved)) == len(flights(hops)) == 2
    from simdiff.motion.gravity_readout import flight_fits

    for fit in flight_fits(moved):
        assert abs(fit.gravity / -3.7 - 1) < 0.05


def test_padding_after_a_row_s_length_is_left_alone_and_does_not_change_its_flights() -> None:
    feats = jump_features()
    n = feats.shape[0]
    mean, std = torch.zeros(263), torch.ones(263)
    padded = torch.cat([feats, torch.full((40, 263), 5.0)])[None]  # garbage frames after the motion
    alone = FlightGuide([-1.6], mean, std, passes=3)(feats[None], 0, feats[None])
    out = FlightGuide([-1.6], mean, std, passes=3, lengths=[n])(padded, 0, padded)
    assert torch.equal(out[0, n:], padded[0, n:])
    assert torch.allclose(out[0, :n], alone[0], atol=1e-6)


def test_a_categorical_model_refuses_flight_guidance_in_one_line() -> None:
    from simdiff.train.testing import tiny_generator

    gen = tiny_generator()
    gen.config.sim.mode = "categorical"  # φ as a category: no gravity to bend the flights to
    with pytest.raises(SimdiffError, match="flight-passes"):
        gen.generate(["a jump"], 20, SamplingConfig(steps=2, guidance=1.0, flight_passes=3), env_index=1, seed=0)
