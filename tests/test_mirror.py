"""Tests for simdiff.motion.mirror."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import torch

from simdiff.errors import SimdiffError
from simdiff.motion.mirror import mirror_caption, mirror_feature_channels, mirror_features, mirror_joints
from simdiff.motion.skeleton import BONE_LENGTHS, PARENTS


def test_mirror_joints_negates_x_and_swaps_chains() -> None:
    joints = np.arange(2 * 22 * 3, dtype=np.float32).reshape(2, 22, 3)
    out = mirror_joints(joints)
    # left hip (1) takes the right hip (2) and vice versa; x negated, y z kept.
    np.testing.assert_array_equal(out[1, 1], [-joints[1, 2, 0], joints[1, 2, 1], joints[1, 2, 2]])
    np.testing.assert_array_equal(out[0, 21], [-joints[0, 20, 0], joints[0, 20, 1], joints[0, 20, 2]])
    np.testing.assert_array_equal(out[0, 15], [-joints[0, 15, 0], joints[0, 15, 1], joints[0, 15, 2]])
    np.testing.assert_array_equal(mirror_joints(out), joints)
    assert joints[0, 1, 0] == 3.0  # input untouched
    t = mirror_joints(torch.from_numpy(joints))
    assert isinstance(t, torch.Tensor)
    np.testing.assert_array_equal(t.numpy(), out)
    with pytest.raises(SimdiffError, match=r"\(5, 21, 3\)"):
        mirror_joints(np.zeros((5, 21, 3)))


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("a person turns left", "a person turns right"),
        ("Left hand up, then RIGHT foot forward", "Right hand up, then LEFT foot forward"),
        ("steps leftwards and then rightward", "steps rightwards and then leftward"),
        ("a left-handed throw to the right.", "a right-handed throw to the left."),
        ("the leftover light is bright; copyright", "the leftover light is bright; copyright"),
        ("left/ADJ arm/NOUN", "right/ADJ arm/NOUN"),
        ("", ""),
    ],
)
def test_mirror_caption(text: str, expected: str) -> None:
    assert mirror_caption(text) == expected
    assert mirror_caption(mirror_caption(text)) == text


def test_mirror_caption_rejects_non_string() -> None:
    with pytest.raises(SimdiffError, match="int"):
        mirror_caption(3)  # type: ignore[arg-type]


def test_feature_channels_by_hand() -> None:
    f = np.zeros((1, 263), dtype=np.float32)
    f[0, 0], f[0, 1], f[0, 2], f[0, 3] = 0.1, 0.2, 0.3, 0.9
    f[0, 4:7] = [0.5, 0.6, 0.7]  # ric of joint 1 (left hip) -> goes to joint 2's slot
    f[0, 67:73] = [1, 2, 3, 4, 5, 6]  # rot6d of joint 1
    f[0, 193:196] = [0.01, 0.02, 0.03]  # velocity of joint 0 (pelvis) stays
    f[0, 259:263] = [1, 0, 0, 1]
    g = mirror_feature_channels(f)
    np.testing.assert_allclose(g[0, :4], [-0.1, -0.2, 0.3, 0.9])
    np.testing.assert_allclose(g[0, 7:10], [-0.5, 0.6, 0.7])
    np.testing.assert_allclose(g[0, 4:7], 0.0)
    np.testing.assert_allclose(g[0, 73:79], [1, -2, -3, -4, 5, 6])
    np.testing.assert_allclose(g[0, 193:196], [-0.01, 0.02, 0.03])
    np.testing.assert_array_equal(g[0, 259:263], [0, 1, 1, 0])
    batch = np.random.default_rng(0).normal(size=(2, 3, 263)).astype(np.float32)
    np.testing.assert_array_equal(mirror_feature_channels(mirror_feature_channels(batch)), batch)
    gt = mirror_feature_channels(torch.from_numpy(batch))
    np.testing.assert_array_equal(gt.numpy(), mirror_feature_channels(batch))


def test_feature_channels_match_joint_pipeline_on_synthetic_walk() -> None:
    features_mod = pytest.importorskip("simdiff.motion.features")
    synthetic = pytest.importorskip("simdiff.motion.synthetic")
    joints = synthetic.walk(60, turn_rate=0.6)
    f = features_mod.joints_to_features(joints)
    exact = mirror_features(f, uniform_skeleton=False)
    assert exact.shape == (59, 263) and exact.dtype == np.float32
    np.testing.assert_allclose(exact, mirror_feature_channels(f), atol=2e-5)


def test_mirror_features_on_real_clip(shared_data: Path) -> None:
    features_mod = pytest.importorskip("simdiff.motion.features")
    sample = shared_data / "humanml3d" / "samples"
    f = np.load(sample / "new_joint_vecs" / "012314.npy")
    # Without retargeting the joint pipeline is exactly the channel mirror.
    exact = mirror_features(f, uniform_skeleton=False)
    assert exact.shape == f.shape
    np.testing.assert_allclose(exact, mirror_feature_channels(f), atol=1e-5)
    # Default (HumanML3D's M-clip processing): the mirrored body is retargeted, so its
    # recovered bones have the canonical lengths again, not the swapped ones.
    mirrored = mirror_features(f)
    assert mirrored.shape == f.shape
    joints = features_mod.features_to_joints(mirrored)
    bones = np.linalg.norm(joints[:, 1:] - joints[:, list(PARENTS[1:])], axis=-1)
    np.testing.assert_allclose(bones.mean(axis=0), BONE_LENGTHS[1:], atol=2e-3)
    # Joint positions match the mirrored original up to the small bone-length change.
    expect = mirror_joints(features_mod.features_to_joints(f))
    root_err = np.abs(joints[:, 0, 1] - expect[:, 0, 1]).max()
    assert root_err < 0.02


def test_mirror_caption_swaps_turn_direction():
    from simdiff.motion.mirror import mirror_caption

    assert mirror_caption("turns clockwise, then Counterclockwise") == "turns counterclockwise, then Clockwise"
    assert mirror_caption("spins anti-clockwise") == "spins clockwise"
