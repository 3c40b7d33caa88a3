"""The slip guard (the swing leg gives way when the stance foot nears sliding) and the finish's second try."""

from __future__ import annotations

import math

import numpy as np
import pytest

from simdiff.errors import SimdiffError
from simdiff.sim.fallback import FallbackConfig, better_rollout
from simdiff.sim.tracker import PDTrackerConfig, SlipGuardConfig


def test_slip_guard_pull_is_full_below_start_and_falls_linearly_to_its_floor_at_mu():
    g = SlipGuardConfig(start=0.5, floor=0.0)
    assert g.pull(0.0, 0.9) == 1.0 and g.pull(0.45, 0.9) == 1.0  # up to start·μ
    assert g.pull(0.675, 0.9) == pytest.approx(0.5)  # halfway to μ
    assert g.pull(0.9, 0.9) == pytest.approx(0.0) and g.pull(2.0, 0.9) == 0.0
    assert SlipGuardConfig(start=0.5, floor=0.3).pull(0.9, 0.9) == 0.3  # bounded below
    assert g.pull(5.0, 0.0) == 1.0  # no friction information: no guard


@pytest.mark.parametrize("kw, msg", [({"start": 1.0}, "slip guard start must be in"),
                                     ({"start": -0.1}, "slip guard start must be in"),
                                     ({"floor": 1.5}, "slip guard floor must be in"),
                                     ({"floor": float("nan")}, "slip guard floor must be in")])
def test_slip_guard_rejects_out_of_range_settings(kw, msg):
    with pytest.raises(SimdiffError, match=msg):
        SlipGuardConfig(**kw)


def test_fallback_retries_falls_and_sliding_above_its_trigger():
    f = FallbackConfig(PDTrackerConfig(), sliding_trigger=0.5)
    assert f.should_retry("fell", 0.1) and f.should_retry("unstable", 0.0)
    assert f.should_retry("ok", 0.51) and f.should_retry("ok", float("nan"))
    assert not f.should_retry("ok", 0.5) and not f.should_retry("ok", 0.2)
    for bad in (-1.0, float("nan"), math.inf):
        with pytest.raises(SimdiffError, match="fallback sliding_trigger must be a finite number >= 0"):
            FallbackConfig(PDTrackerConfig(), sliding_trigger=bad)


def test_the_better_rollout_is_tracked_to_the_end_then_slides_less():
    assert better_rollout(("fell", 0.1), ("ok", 0.9))  # a finished rollout over a fall
    assert not better_rollout(("ok", 0.9), ("fell", 0.1))
    assert better_rollout(("ok", 0.6), ("ok", 0.4)) and not better_rollout(("ok", 0.4), ("ok", 0.6))
    assert not better_rollout(("ok", 0.4), ("ok", 0.4))  # a tie keeps the first
    assert better_rollout(("fell", 0.5), ("fell", 0.3))
    assert not better_rollout(("ok", 0.4), ("ok", float("nan")))


def test_the_finish_fallback_is_the_finish_tracker_with_the_slip_guard(monkeypatch):
    from dataclasses import replace

    import simdiff.sim.fallback as fallback
    from simdiff.sim.slip_guard import FINISH_SLIP_GUARD
    from simdiff.sim.tracker import finish_tracker_config

    f = fallback.finish_fallback()
    assert f.tracker_config == replace(finish_tracker_config(), slip_guard=FINISH_SLIP_GUARD)
    assert FINISH_SLIP_GUARD == SlipGuardConfig(start=0.5, floor=0.0)
    assert f.sliding_trigger == fallback.FINISH_FALLBACK_SLIDING == 0.5
    assert finish_tracker_config().slip_guard is None and PDTrackerConfig().slip_guard is None  # first try, mocap
    monkeypatch.setattr(fallback, "FINISH_FALLBACK", False)
    assert fallback.finish_fallback() is None


def test_finish_summary_counts_second_tries_and_kept_fallbacks():
    from simdiff.eval.protocol import finish_summary

    log = [{"success": True, "attempts": 1, "fallback": False}, {"success": True, "attempts": 2, "fallback": True},
           {"success": False, "attempts": 2, "fallback": False}, {"success": True}]  # an older log: one try
    assert finish_summary(log) == {"motions": 4, "tracked": 3, "tracked_frac": 0.75, "second_tries": 2,
                                   "fallback_kept": 1}


mujoco = pytest.importorskip("mujoco")


def _standing_tracker(config: PDTrackerConfig):
    from simdiff.sim import synthetic
    from simdiff.sim.humanoid import load_model, model_index
    from simdiff.sim.retarget import make_reference
    from simdiff.sim.tracker import PDTracker

    model = load_model()
    ref = make_reference(model, synthetic.standing(20))
    data = mujoco.MjData(model)
    data.qpos[:] = ref.qpos[0]
    mujoco.mj_forward(model, data)
    t = PDTracker(config)
    ix = model_index(model)
    t.reset(model, data, ref, ix)
    return model, data, ref, ix, t


def test_stance_forces_carry_the_weight_and_grow_with_a_push():
    """Standing still on both feet the floor's normal forces sum to m·g with little horizontal force;
    a horizontal push on the pelvis is met by horizontal friction at the feet; μ is the contact's (0.9)."""
    model, data, ref, ix, t = _standing_tracker(PDTrackerConfig())
    for _ in range(200):
        data.ctrl[:] = ref.qpos[0, 7:]
        mujoco.mj_step(model, data)
    fn, ft, mu = t.stance_forces(data)
    assert fn.sum() == pytest.approx(ix.mass * 9.81, rel=0.05) and (fn > 0.3 * ix.mass * 9.81).all()
    assert ft.sum() < 0.02 * fn.sum()
    np.testing.assert_allclose(mu, [0.9, 0.9])
    data.xfrc_applied[ix.pelvis, 0] = 100.0
    for _ in range(30):
        data.ctrl[:] = ref.qpos[0, 7:]
        mujoco.mj_step(model, data)
    assert t.stance_forces(data)[1].sum() > 5 * ft.sum()


def test_the_guard_pulls_only_the_swing_leg_toward_its_angles(monkeypatch):
    """One stance foot (left) at a force ratio of 0.675 = halfway from 0.5·μ to μ: the right hip and knee
    targets move halfway to their current angles; every other target, and both feet down, are untouched."""
    from simdiff.sim.tracker import PDTracker

    model, data, ref, ix, t = _standing_tracker(PDTrackerConfig(slip_guard=SlipGuardConfig(0.5, 0.0)))
    target = np.linspace(-0.5, 0.5, 69)
    data.qpos[7:] = 0.1
    forces = (np.array([600.0, 0.0]), np.array([405.0, 0.0]), np.array([0.9, 0.0]))
    monkeypatch.setattr(PDTracker, "stance_forces", lambda self, d: forces)
    out = target.copy()
    t._guard_slip(data, out)
    right = t.swing_dofs[1]
    np.testing.assert_allclose(out[right], 0.1 + 0.5 * (target[right] - 0.1), atol=1e-12)
    others = np.setdiff1d(np.arange(69), right)
    np.testing.assert_array_equal(out[others], target[others])
    both = (np.array([300.0, 300.0]), np.array([400.0, 400.0]), np.array([0.9, 0.9]))
    monkeypatch.setattr(PDTracker, "stance_forces", lambda self, d: both)
    out = target.copy()
    t._guard_slip(data, out)
    np.testing.assert_array_equal(out, target)


def test_project_keeps_the_better_of_the_two_rollouts():
    """With a trigger of 0 every rollout earns a second try; project returns exactly the better of the two
    single-try rollouts (here the second tracker stands with a far longer lead) and counts both; with an
    unreachable trigger a tracked rollout is returned as the first try made it."""
    from dataclasses import replace

    from simdiff.sim import synthetic
    from simdiff.sim.env import Environment
    from simdiff.sim.fallback import rollout_sliding
    from simdiff.sim.project import project
    from simdiff.sim.tracker import finish_tracker_config

    motion = synthetic.walk_in_place(40).astype(np.float64)
    a = finish_tracker_config()
    b = replace(a, lead=8.0, slip_guard=SlipGuardConfig())
    out_a, info_a = project(motion, Environment(), tracker_config=a)
    out_b, info_b = project(motion, Environment(), tracker_config=b)
    out, info = project(motion, Environment(), tracker_config=a, fallback=FallbackConfig(b, sliding_trigger=0.0))
    second = better_rollout((info_a.status, rollout_sliding(out_a)), (info_b.status, rollout_sliding(out_b)))
    np.testing.assert_array_equal(out, out_b if second else out_a)
    assert info.fallback is second and info.attempts == 2
    assert info_a.status == info_b.status == "ok" and second  # both tracked; the second slides less here
    assert info.cpu_s > info_b.cpu_s
    out1, info1 = project(motion, Environment(), tracker_config=a, fallback=FallbackConfig(b, sliding_trigger=1e9))
    np.testing.assert_array_equal(out1, out_a)
    assert info1.attempts == 1 and not info1.fallback
