"""Joints ⇄ humanoid conversions: IK round trip, stance pass, filtering, features, ID screen."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("mujoco")

from simdiff.errors import SimdiffError  # noqa: E402
from simdiff.sim import synthetic  # noqa: E402
from simdiff.sim.humanoid import load_model, model_index  # noqa: E402
from simdiff.sim.retarget import RetargetConfig, make_reference, qpos_to_joints  # noqa: E402
from simdiff.sim.retarget.filtering import resample_qpos, smooth  # noqa: E402


def test_roundtrip_synthetic_squat():
    m = load_model()
    joints = synthetic.squat(40)
    ref = make_reference(m, joints)
    assert ref.qpos.shape == (int(np.ceil(39 * 1.5)) + 1, 76)
    back = qpos_to_joints(m, ref.qpos)  # 30 Hz; every 3rd frame is an even 20-fps frame
    assert back.dtype == np.float32
    err = np.linalg.norm(back[::3] - joints[::2][: len(back[::3])] - [0, ref.ground_shift, 0], axis=-1)
    assert err.mean() < 0.02
    assert abs(ref.ground_shift) < 0.01
    assert ref.contact.all()  # both feet flat on the floor throughout
    feas = ref.feasibility(model_index(m).mass)
    assert feas["force_p90_mg"] < 0.05  # a slow squat is dynamically feasible


def test_stance_feet_held_flat_on_floor():
    m = load_model()
    ref = make_reference(m, synthetic.walk_in_place(40))
    from simdiff.sim.retarget.kinematics import foot_heights

    h, _ = foot_heights(m, ref.qpos)
    stance = h[ref.contact]
    # flat stance frames are held on the floor; at heel rise the pitched box is released
    # (not forced flat), so its toe end may dip a little
    assert np.median(np.abs(stance)) < 0.002
    assert np.percentile(np.abs(stance), 75) < 0.015
    assert stance.min() > -0.03


def test_smoothing_keeps_boundary_velocity():
    t = np.arange(20, dtype=float)[:, None]
    x = 0.3 * t  # a ramp: odd-reflection padding leaves it unchanged
    assert np.allclose(smooth(x, 1.5), x)


def test_resample_lengths():
    q = np.zeros((21, 76))
    q[:, 3] = 1.0
    q[:, 0] = np.arange(21) / 20.0  # 1 m/s for 1 s
    r = resample_qpos(q, 20.0, 30.0)
    assert r.shape[0] == 31
    assert np.allclose(r[:, 0], np.arange(31) / 30.0)


def test_bad_input():
    m = load_model()
    with pytest.raises(SimdiffError):
        make_reference(m, np.zeros((10, 21, 3)))
    with pytest.raises(SimdiffError):
        make_reference(m, np.zeros((2, 22, 3)))
    bad = synthetic.standing(10).astype(float)
    bad[3, 4, 1] = np.nan
    with pytest.raises(SimdiffError):
        make_reference(m, bad)


def test_features_roundtrip_shape():
    pytest.importorskip("simdiff.motion.features")
    from simdiff.sim.retarget.kinematics import joints_to_features

    m = load_model()
    joints = synthetic.squat(30)
    ref = make_reference(m, joints, RetargetConfig(stance_pass=False))
    back = qpos_to_joints(m, ref.qpos[::3])
    f = joints_to_features(back)
    assert f.shape == (back.shape[0] - 1, 263)


def test_real_clip_ik_error(shared_data):
    m = load_model()
    joints = np.load(shared_data / "humanml3d" / "samples" / "new_joints" / "012314.npy")[:60]
    ref = make_reference(m, joints)
    assert np.median(ref.ik_error) < 0.03  # metres; arms above the head are the worst frames


def test_analytic_ik_recovers_in_range_poses():
    from simdiff.sim.retarget.kinematics import qpos_to_world
    from simdiff.sim.retarget.ik import analytic_ik

    m = load_model()
    rng = np.random.default_rng(0)
    q = np.tile(m.qpos0, (8, 1))
    lo, hi = m.jnt_range[1:, 0], m.jnt_range[1:, 1]
    q[:, 7:] = rng.uniform(0.7 * lo, 0.7 * hi, size=(8, 69))
    q[:, :3] = [0.3, -0.2, 1.0]
    q[:, 3:7] = [np.cos(0.4), 0.0, 0.0, np.sin(0.4)]  # 46° yaw
    target = qpos_to_world(m, q)
    got = qpos_to_world(m, analytic_ik(m, target))
    err = np.linalg.norm(got - target, axis=-1)
    assert err.mean() < 0.02 and np.median(err) < 0.005  # exact up to twist / range corner cases


def test_analytic_ik_continuous_on_synthetic_walk():
    from simdiff.sim.humanoid import hml_to_world
    from simdiff.sim.retarget.ik import analytic_ik

    m = load_model()
    q = analytic_ik(m, hml_to_world(synthetic.walk_in_place(40).astype(float)))
    assert np.abs(np.diff(q[:, 7:], axis=0)).max() < 1.0  # no Euler-branch / twist flips (≈ π)


def testdespike_replaces_isolated_glitch_only():
    from simdiff.sim.retarget.filtering import despike

    j = synthetic.walk_in_place(30).astype(float)
    bad = j.copy()
    bad[0, 20] += [0.0, 0.0, 0.7]  # first frame wrist glitch (seen in CMU 16_15)
    bad[12, 7] += [0.4, 0.0, 0.0]
    out = despike(bad, 0.25)
    assert np.linalg.norm(out[0, 20] - j[0, 20]) < 0.05
    assert np.linalg.norm(out[12, 7] - j[12, 7]) < 0.05
    assert np.array_equal(despike(j, 0.25), j)  # clean motion untouched


def test_ground_level_uses_planted_feet():
    from simdiff.sim.retarget.contacts import ground_level

    T = 60
    h = np.full((T, 4), 0.12)  # feet planted 12 cm above the capture's zero ...
    h[30:33, 3] = -0.02  # ... except a brief toe dip while sliding fast
    xy = np.zeros((T, 4, 2))
    xy[29:34, 3, 0] = np.linspace(0, 0.5, 5)
    assert ground_level(h, xy, 20.0) == pytest.approx(0.12)
