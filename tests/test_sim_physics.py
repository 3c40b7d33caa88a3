"""Physics validity of rollouts: force invariants, the airborne-zero residual, instability, a short tracked clip."""

from __future__ import annotations

import copy

import numpy as np
import pytest

pytest.importorskip("mujoco")

from simdiff.sim import synthetic  # noqa: E402
from simdiff.sim.retarget import make_reference  # noqa: E402
from simdiff.sim.env import Environment  # noqa: E402
from simdiff.sim.humanoid import load_model  # noqa: E402
from simdiff.sim.project import project  # noqa: E402
from simdiff.sim.residual import ResidualConfig  # noqa: E402
from simdiff.sim.rollout import rollout  # noqa: E402


@pytest.fixture(scope="module")
def squat_ref():
    return make_reference(load_model(), synthetic.squat(30))


def test_invariants_hold_every_step(squat_ref):
    for env in (Environment(), Environment(-3.0, 10.0, 0.0), Environment(-15.0, 0.0, -10.0)):
        res = rollout(load_model(), squat_ref, env, audit=True)
        assert res.violations == []
        assert res.success
        assert res.residual.shape[0] == res.qpos.shape[0] - 1


def test_residual_zero_while_airborne_and_on_after_landing(squat_ref):
    ref = copy.deepcopy(squat_ref)
    ref.qpos[:, 2] += 0.25  # start 25 cm above the floor: ~0.23 s of free fall
    res = rollout(load_model(), ref, Environment(), audit=True)
    assert res.violations == []
    assert res.airborne[:50].all()
    assert np.all(res.residual[res.airborne] == 0.0)
    assert np.any(res.residual[~res.airborne] != 0.0)  # the gate does open on contact
    # free fall: the COM's vertical motion over the airborne steps is ballistic
    import mujoco

    m = load_model()
    d = mujoco.MjData(m)
    n = int(np.argmin(res.airborne))

    def com_z(q):
        d.qpos[:] = q
        mujoco.mj_kinematics(m, d)
        mujoco.mj_comPos(m, d)
        return d.subtree_com[1, 2]

    vz0 = 0.0
    t = n * res.timestep
    assert com_z(res.qpos[0]) - com_z(res.qpos[n]) == pytest.approx(0.5 * 9.81 * t**2 - vz0 * t, rel=0.03)


def test_strict_has_no_residual(squat_ref):
    res = rollout(load_model(), squat_ref, Environment(), residual=ResidualConfig(max_force=0.0), audit=True)
    assert np.all(res.residual == 0.0)
    assert res.violations == []


def test_residual_bounds(squat_ref):
    cfg = ResidualConfig(max_force=0.1)
    ref = copy.deepcopy(squat_ref)
    ref.com[:, 2] += 0.3  # an unreachable COM height: the residual saturates
    res = rollout(load_model(), ref, Environment(), residual=cfg, audit=True)
    f = np.linalg.norm(res.residual[:, :3], axis=1)
    assert f.max() <= 0.1 * res.mass * 9.81 + 1e-6
    assert f.max() > 0.09 * res.mass * 9.81
    assert np.all(res.residual[:, 2] >= 0.0)  # vertical part push-only
    assert np.linalg.norm(res.residual[:, 3:], axis=1).max() <= 60.0 + 1e-6


def test_instability_is_a_failure(squat_ref):
    ref = copy.deepcopy(squat_ref)
    ref.qvel[0, :] = 1e9  # absurd initial velocity
    res = rollout(load_model(), ref, Environment())
    assert res.status in ("unstable", "fell")
    assert not res.success


def test_short_tracked_clip():
    out, info = project(synthetic.squat(40), Environment(), audit=True)
    assert info.success and info.fall_frame is None
    assert out.shape == (40, 22, 3) and out.dtype == np.float32
    assert info.err_mm < 60
    assert info.residual["force_mean_mg"] < 0.1
    assert info.residual["airborne_force_max_n"] == 0.0
    assert info.violations == []


def test_real_clip_tracked(shared_data):
    from simdiff.motion.normalize import Normalizer

    joints = np.load(shared_data / "humanml3d" / "samples" / "new_joints" / "012314.npy")[:60]
    out, info = project(joints, Environment(), normalizer=Normalizer.from_dir(shared_data / "humanml3d"), audit=True)
    assert info.violations == []
    assert info.success
    assert np.isfinite(info.d_l2) and info.d_l2 < 10


def test_balance_layer_quiet_on_reference_and_pushes_back(squat_ref):
    """On the reference state the balance layer adds (almost) nothing; with the COM pushed
    forward it asks the stance legs for a backward ground force (ankles plantarflex)."""
    import mujoco

    from simdiff.sim.humanoid import model_index
    from simdiff.sim.tracker import PDTracker, PDTrackerConfig

    m = load_model()
    d = mujoco.MjData(m)
    d.qpos[:] = squat_ref.qpos[0]
    d.qpos[2] -= 0.002  # soles 2 mm into the floor: the feet register as touching
    d.qvel[:] = squat_ref.qvel[0]
    mujoco.mj_forward(m, d)
    assert d.ncon > 0
    on, off = PDTracker(), PDTracker(PDTrackerConfig(balance=None))
    for tr in (on, off):
        tr.reset(m, d, squat_ref, model_index(m))
    assert np.abs(on.act(d, 0) - off.act(d, 0)).max() < 0.01
    d.qvel[0] = 0.5  # COM moving forward (+x) relative to the reference
    mujoco.mj_forward(m, d)
    delta = on.act(d, 0) - off.act(d, 0)
    ankles = [on.leg[s][2] for s in ("L", "R")]
    assert np.all(delta[ankles] > 0)  # +y at the ankle = toes down: the CoP moves forward


def test_residual_follows_a_lower_stance_ankle(squat_ref):
    """A body standing lower because its stance ankle is lower than the mocap's (e.g. a foot laid
    flat that the mocap had tilted on an edge) is not held up at the mocap height."""
    import mujoco

    from simdiff.sim.humanoid import model_index
    from simdiff.sim.residual import RootResidual

    m = load_model()
    ix = model_index(m)
    d = mujoco.MjData(m)

    def fz(cfg: ResidualConfig, dz: float) -> float:
        d.qpos[:] = squat_ref.qpos[0]
        d.qpos[2] += dz
        d.qvel[:] = squat_ref.qvel[0]
        mujoco.mj_forward(m, d)
        res = RootResidual(cfg, m, squat_ref, ix, -9.81)
        assert res.sim_support(d)
        return float(res.wrench(d, 0.0)[2])

    shifted = fz(ResidualConfig(z_deadband=0.0), -0.03)
    absolute = fz(ResidualConfig(support_shift_max=0.0, z_deadband=0.0), -0.03)
    assert absolute > 0.2 * ix.mass * 9.81  # kp_z · 3 cm ≈ 0.3·m·g at the mocap height
    assert shifted < 0.1 * absolute
    # the height deadband: a sag within it is left to the legs, beyond it only the excess counts
    band = ResidualConfig(support_shift_max=0.0, z_deadband=0.01)
    assert fz(band, -0.006) < 0.01 * ix.mass * 9.81
    assert fz(band, -0.03) == pytest.approx(absolute * 2 / 3, rel=0.1)
