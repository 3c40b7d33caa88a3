"""joints ⇄ 263-dim features: exactness on a real HumanML3D clip and on synthetic motions."""

from __future__ import annotations

import numpy as np
import pytest

from simdiff.errors import SimdiffError
from simdiff.motion import synthetic
from simdiff.motion.features import (
    FEATURE_DIM,
    SLICES,
    canonicalize,
    extend_last_frame,
    features_to_joints,
    features_to_joints_fk,
    joints_to_features,
    process_joints,
    retarget_uniform,
)
from simdiff.motion.skeleton import BONE_LENGTHS, PARENTS

# Acceptance tolerances (root ≤ 1e-6, ric ≤ 1e-5, rot6d ≤ 5e-5, vel ≤ 1e-5, contacts exact).
TOLERANCES = {
    "root_rot_vel": 1e-6,
    "root_lin_vel": 1e-6,
    "root_y": 1e-6,
    "ric": 1e-5,
    "rot6d": 5e-5,
    "vel": 1e-5,
    "contacts": 0.0,
}


@pytest.fixture(scope="module")
def clip_012314(shared_data):
    base = shared_data / "humanml3d" / "samples"
    feats = np.load(base / "new_joint_vecs" / "012314.npy")
    joints = np.load(base / "new_joints" / "012314.npy")
    return feats, joints


def group_errors(a: np.ndarray, b: np.ndarray) -> dict[str, float]:
    return {name: float(np.abs(a[:, s] - b[:, s]).max()) for name, s in SLICES.items()}


def test_recover_from_ric_matches_shipped_joints(clip_012314):
    feats, joints = clip_012314
    recovered = features_to_joints(feats)
    assert recovered.shape == joints.shape == (170, 22, 3)
    assert np.abs(recovered - joints).max() <= 1e-6


def test_fk_from_rot6d_matches_shipped_joints(clip_012314):
    feats, joints = clip_012314
    assert np.abs(features_to_joints_fk(feats) - joints).max() <= 1e-5


def test_joints_to_features_reproduces_shipped_features(clip_012314):
    feats, joints = clip_012314
    full = extend_last_frame(joints, feats)
    assert full.shape == (171, 22, 3)
    ours = joints_to_features(full)
    assert ours.shape == feats.shape and ours.dtype == np.float32
    errors = group_errors(ours, feats)
    for name, tol in TOLERANCES.items():
        assert errors[name] <= tol, (name, errors[name])


def test_hip_quirk_is_what_matches_the_dataset(clip_012314):
    feats, joints = clip_012314
    fixed = joints_to_features(extend_last_frame(joints, feats), hip_quirk=False)
    errors = group_errors(fixed, feats)
    assert errors["ric"] > 0.1 and errors["rot6d"] > 0.1


def test_uniform_skeleton_is_a_no_op_on_uniform_clips(clip_012314):
    _, joints = clip_012314
    retargeted = retarget_uniform(joints)
    assert np.abs(retargeted - joints).max() < 2e-5


def test_synthetic_round_trip_all_recoveries():
    joints = synthetic.walk(60, turn_rate=0.7)
    processed = process_joints(joints)
    feats = processed.features
    assert feats.shape == (59, FEATURE_DIM)
    canon = processed.joints
    np.testing.assert_allclose(features_to_joints(feats), canon[:-1], atol=1e-5)
    np.testing.assert_allclose(features_to_joints_fk(feats), canon[:-1], atol=1e-5)
    np.testing.assert_allclose(extend_last_frame(canon[:-1], feats), canon, atol=1e-5)
    # Features of the canonical joints are the same features (idempotent processing).
    np.testing.assert_allclose(joints_to_features(canon), feats, atol=2e-5)


def test_canonical_frame_conventions():
    rng = np.random.default_rng(0)
    joints = synthetic.walk(40, turn_rate=0.3).astype(np.float64)
    yaw = 1.1
    rot = np.array([[np.cos(yaw), 0, np.sin(yaw)], [0, 1, 0], [-np.sin(yaw), 0, np.cos(yaw)]])
    moved = joints @ rot.T + np.array([3.0, 0.5, -2.0]) + rng.normal(0, 0, 3)
    canon = canonicalize(moved)
    assert abs(canon[..., 1].min()) < 1e-9
    np.testing.assert_allclose(canon[0, 0, [0, 2]], 0.0, atol=1e-9)
    across = (canon[0, 2] - canon[0, 1]) + (canon[0, 17] - canon[0, 16])
    forward = np.cross([0, 1, 0], across)
    forward /= np.linalg.norm(forward)
    np.testing.assert_allclose(forward, [0, 0, 1], atol=1e-9)
    # Left is +X when facing +Z.
    assert canon[0, 1, 0] > canon[0, 2, 0]


def test_uniform_retarget_sets_canonical_bone_lengths_and_scales_root():
    joints = synthetic.walk(30).astype(np.float64) * 1.2  # a taller person
    out = retarget_uniform(joints)
    lengths = np.linalg.norm(out[:, 1:] - out[:, list(PARENTS[1:])], axis=-1)
    np.testing.assert_allclose(lengths, np.broadcast_to(BONE_LENGTHS[1:], lengths.shape), atol=1e-9)
    np.testing.assert_allclose(out[:, 0], joints[:, 0] / 1.2, atol=1e-9)


def test_root_channels_have_physical_meaning():
    speed = 1.5  # m/s straight ahead
    feats = joints_to_features(synthetic.walk(40, speed=speed, bounce=0.0))
    np.testing.assert_allclose(feats[:, SLICES["root_lin_vel"]][:, 1], speed / 20, atol=2e-3)
    np.testing.assert_allclose(feats[:, 0], 0.0, atol=1e-4)
    turning = joints_to_features(synthetic.walk(200, speed=1.0, turn_rate=0.5, amplitude=0.0))
    # Half the yaw increment of the world→heading rotation per frame: a left turn (towards
    # +X) is negative. Checked away from the ends, where the σ=20 smoothing clamps.
    np.testing.assert_allclose(turning[60:140, 0], -0.5 / 20 / 2, rtol=0.02)
    # The heading crosses 180° near frame 65; the original code's sign glitch is opt-in.
    glitch = joints_to_features(synthetic.walk(200, speed=1.0, turn_rate=0.5, amplitude=0.0), yaw_sign_fix=False)
    assert np.sum(glitch[60:140, 0] > 0) == 1


def test_foot_contacts_follow_threshold():
    still = np.repeat(synthetic.walk(1), 20, axis=0)
    assert np.all(joints_to_features(still)[:, SLICES["contacts"]] == 1.0)
    sliding = still.copy()
    sliding[:, :, 2] += np.arange(20)[:, None] * 0.05  # 5 cm/frame > sqrt(0.002) ≈ 4.5 cm
    assert np.all(joints_to_features(sliding)[:, SLICES["contacts"]] == 0.0)


def test_batched_torch_recovery_matches_numpy():
    torch = pytest.importorskip("torch")
    feats = np.stack([joints_to_features(synthetic.walk(41, phase=p)) for p in (0.0, 1.0)])
    batched = features_to_joints(torch.from_numpy(feats))
    assert tuple(batched.shape) == (2, 40, 22, 3)
    np.testing.assert_allclose(batched[1].numpy(), features_to_joints(feats[1]), atol=1e-6)


@pytest.mark.parametrize(
    "bad",
    [np.zeros((10, 21, 3)), np.zeros((1, 22, 3)), np.full((5, 22, 3), np.nan)],
    ids=["joints", "one-frame", "nan"],
)
def test_bad_joints_raise_one_line_errors(bad):
    with pytest.raises(SimdiffError) as info:
        joints_to_features(bad)
    assert "\n" not in str(info.value)


def test_bad_features_raise():
    with pytest.raises(SimdiffError, match="263"):
        features_to_joints(np.zeros((10, 262)))
