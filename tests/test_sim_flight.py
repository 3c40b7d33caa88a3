"""The flight clock: the reference waits while the simulation flies, resumes from the landing pose."""

from __future__ import annotations

import numpy as np
import pytest

from simdiff.errors import SimdiffError
from simdiff.motion.flight import runs
from simdiff.sim.flight import FlightClock, FlightConfig, aligned_source, reference_flights


def _contacts(pattern: str) -> np.ndarray:
    """'x' = feet down, '.' = airborne."""
    return np.array([[c == "x"] * 4 for c in pattern])


def test_reference_flights_need_stance_before_and_a_minimum_length():
    assert reference_flights(_contacts("xx...xx.xx")) == [(2, 5)]
    assert reference_flights(_contacts("..xx...x"), min_frames=2) == [(4, 7)]  # no stance before frame 0
    assert reference_flights(_contacts("xx.x"), min_frames=1) == [(2, 3)]
    with pytest.raises(SimdiffError, match="contact"):
        reference_flights(np.zeros(5, dtype=bool))


def _fly(clock: FlightClock, v0: float, g: float, hz: float = 30.0) -> list[int]:
    """Simulate a ballistic COM from the clock's current frame: airborne until v_z = −v0."""
    frames, n = [], 1
    while True:
        vz = v0 - g * n / hz
        if vz <= -v0:
            frames.append(clock.advance(True, vz))
            return frames
        frames.append(clock.advance(False, vz))
        n += 1


def test_long_flight_waits_at_the_last_airborne_frame_then_lands():
    c = _contacts("xxx" + "." * 6 + "xxxx")  # reference flight [3, 9)
    clock = FlightClock(c)
    assert [clock.advance(True, 0.0) for _ in range(3)] == [1, 2, 3]
    frames = _fly(clock, v0=1.5, g=1.6)  # about 1.9 s in the air instead of 0.2 s
    assert len(frames) > 50
    air = frames[:-1]
    assert all(3 <= f <= 8 for f in air) and air == sorted(air)  # monotone, inside the flight
    assert air[-1] == 8 and frames[-1] == 9  # waited at e − 1, resumed at the landing frame
    assert clock.extra_steps == len(frames) - 6
    while not clock.done:
        clock.advance(True, 0.0)
    assert clock.frame == len(c) - 1


def test_short_flight_jumps_to_the_landing_frame():
    c = _contacts("xxx" + "." * 10 + "xxx")  # reference flight [3, 13)
    clock = FlightClock(c)
    for _ in range(3):
        clock.advance(True, 0.0)
    frames = _fly(clock, v0=1.0, g=20.0)  # 0.1 s
    assert frames[-1] == 13  # early touchdown: the landing pose
    assert clock.extra_steps < 0  # the rollout is shorter than the reference


def test_the_flight_progress_follows_the_simulated_velocity():
    c = _contacts("xx" + "." * 10 + "xx")
    clock = FlightClock(c)
    clock.advance(True, 0.0)
    clock.advance(True, 0.0)  # at the first flight frame
    clock.advance(False, 2.0)  # take-off v0 = 2
    assert clock.advance(False, 0.0) == 2 + 5  # apex: half the flight
    assert clock.advance(False, -1.0) == 2 + 7


def test_hop_in_stance_holds_after_hold_after_steps_and_is_bounded():
    c = _contacts("x" * 20)
    clock = FlightClock(c, config=FlightConfig(hold_after=2, max_wait_s=0.1))  # 3 control steps
    assert clock.advance(False, 1.0) == 1  # one step in the air: a bounce, the clock goes on
    assert [clock.advance(False, 0.5) for _ in range(5)] == [1, 1, 1, 2, 3]
    assert clock.advance(True, -1.0) == 4


def test_total_extension_is_bounded():
    c = _contacts("xx" + "." * 4 + "xx")
    clock = FlightClock(c, config=FlightConfig(max_extra_s=1.0, max_wait_s=100.0))
    n = 0
    while not clock.done:
        clock.advance(False, 1.0)  # never lands
        n += 1
    assert n == len(c) - 1 + 30


def test_aligned_source_holds_the_source_while_the_clock_waits():
    T = 11
    joints = np.zeros((T, 22, 3), dtype=np.float32)
    joints[:, 0, 0] = np.arange(T)  # root x = source frame index (20 fps)
    frames = np.array([0, 1, 2, 3, 3, 3, 3, 4, 5, 6, 7, 8])  # control steps at 30 Hz; a wait at frame 3
    src = aligned_source(joints, frames, 30.0, 20.0, 7)[:, 0, 0]
    assert np.allclose(src[:2], [0.0, 1.0])  # 0.05 s → control step 1.5 → reference 0.05 s → source frame 1
    assert np.allclose(src[2:5], 2.0)  # 0.10–0.20 s: held at reference frame 3 (0.1 s → source frame 2)
    assert np.allclose(src[5:], [3.0, 4.0])  # then on at the normal rate


def _longest_flight(res) -> tuple[int, int]:
    found = runs(res.airborne)
    return max(found, key=lambda r: r[1] - r[0]) if found else (0, 0)


def test_synthetic_jump_follows_ballistics_at_three_gravities_and_lands():
    pytest.importorskip("mujoco")
    import mujoco

    from simdiff.sim import synthetic
    from simdiff.sim.env import Environment
    from simdiff.sim.humanoid import load_model
    from simdiff.sim.retarget import make_reference
    from simdiff.sim.rollout import rollout

    m = load_model()
    jump = synthetic.vertical_jump(height=0.3)
    d = mujoco.MjData(m)
    norm, flight = {}, {}
    for g in (-1.6, -3.0, -9.81):
        ref = make_reference(m, jump, gravity=g)
        res = rollout(m, ref, Environment(g), flight=FlightConfig(), audit=True)
        assert res.status == "ok", g  # lands without a fall and finishes the motion
        assert not res.violations and not np.any(res.residual[res.airborne])
        assert res.ref_frames[-1] == ref.num_frames - 1
        s, e = _longest_flight(res)
        com = []
        for q in res.qpos[s : s + 2]:
            d.qpos[:] = q
            mujoco.mj_kinematics(m, d)
            mujoco.mj_comPos(m, d)
            com.append(d.subtree_com[1, 2])
        v = (com[1] - com[0]) / res.timestep  # simulated take-off speed (m/s)
        assert v > 0.3, g
        flight[g] = (e - s) * res.timestep
        norm[g] = flight[g] * abs(g) / v  # ballistic: 2 for a landing at the take-off height
    assert flight[-1.6] > 3 * flight[-9.81]  # the clock let the long flight happen
    vals = np.array(list(norm.values()))
    assert vals.max() / vals.min() < 1.1, norm  # same take-off speed → flight time ∝ 1/|g|, within 10 %
    assert np.all(np.abs(vals / 2 - 1) < 0.2), norm


def test_clock_log_matches_the_states_also_with_recovery():
    pytest.importorskip("mujoco")
    from simdiff.sim import synthetic
    from simdiff.sim.env import Environment
    from simdiff.sim.humanoid import load_model
    from simdiff.sim.retarget import make_reference
    from simdiff.sim.rollout import RecoveryConfig, rollout

    m = load_model()
    ref = make_reference(m, synthetic.vertical_jump(height=0.3), gravity=-3.0)
    for recovery in (None, RecoveryConfig()):
        res = rollout(m, ref, Environment(-3.0), flight=FlightConfig(), recovery=recovery)
        n_sub = round(res.control_dt / res.timestep)
        assert len(res.ref_frames) == (len(res.qpos) - 1) // n_sub + 1
        assert np.all(np.diff(res.ref_frames) >= 0) and res.ref_frames[0] == 0
        assert len(res.ref_frames) > ref.num_frames  # the low-g flight made the rollout longer
