"""Fall recovery (rewind and re-simulate with another tracker setting) and the tracker's lead."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("mujoco")

from simdiff.sim import synthetic  # noqa: E402
from simdiff.sim.retarget import make_reference  # noqa: E402
from simdiff.sim.env import Environment  # noqa: E402
from simdiff.sim.humanoid import load_model, model_index  # noqa: E402
from simdiff.sim.rollout import FallConfig, RecoveryConfig, rollout  # noqa: E402
from simdiff.sim.tracker import PDTracker, PDTrackerConfig  # noqa: E402


@pytest.fixture(scope="module")
def squat_ref():
    return make_reference(load_model(), synthetic.squat(20))


def test_recovery_does_not_touch_a_rollout_without_falls(squat_ref):
    a = rollout(load_model(), squat_ref, Environment(), recovery=None)
    b = rollout(load_model(), squat_ref, Environment(), recovery=RecoveryConfig(), audit=True)
    assert a.success and b.success and b.recoveries == 0
    np.testing.assert_array_equal(a.qpos, b.qpos)  # saving states does not perturb the physics
    np.testing.assert_array_equal(a.residual, b.residual)
    assert b.violations == []


def test_recovery_rewinds_and_gives_up_after_max_retries(squat_ref):
    always = FallConfig(max_error=-1.0)  # every control frame counts as a fall
    res = rollout(load_model(), squat_ref, Environment(), fall=always, audit=True,
                  recovery=RecoveryConfig(window=5, max_retries=3))
    assert res.recoveries == 3
    assert res.status == "fell"
    assert res.fall_time == pytest.approx(squat_ref.dt, abs=1e-6)
    n_sub = 15
    assert res.qpos.shape[0] == n_sub + 1  # only the committed first control period is returned
    assert res.residual.shape[0] == n_sub
    assert res.violations == []  # the rewound attempts obey the invariants too


def test_rewind_restores_the_state_exactly(squat_ref):
    """A rewound attempt with the same tracker reproduces the first attempt bit for bit."""
    same = RecoveryConfig(window=1, max_retries=1, variants=(PDTrackerConfig(),))
    always = FallConfig(max_error=-1.0)
    res = rollout(load_model(), squat_ref, Environment(), fall=always, recovery=same)
    ref = rollout(load_model(), squat_ref, Environment(), fall=always, recovery=None)
    np.testing.assert_array_equal(res.qpos, ref.qpos)


def test_lead_interpolates_the_reference(squat_ref):
    m = load_model()
    import mujoco

    d = mujoco.MjData(m)
    t = PDTracker(PDTrackerConfig(lead=1.5))
    t.reset(m, d, squat_ref, model_index(m))
    q = squat_ref.qpos[:, 7:]
    np.testing.assert_allclose(t.q_target[3], 0.5 * (q[4] + q[5]), atol=1e-12)
    np.testing.assert_allclose(t.q_target[-1], q[-1], atol=1e-12)  # clamped at the end
