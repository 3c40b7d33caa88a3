"""Pose d_L2 against the re-timed source: what φ changes (timing, height) is not punished, the pose is."""

from __future__ import annotations

import numpy as np
import pytest

from simdiff.motion.normalize import Normalizer
from simdiff.sim.faithfulness import pose_d_l2, pose_feature_mask
from simdiff.sim.flight import aligned_source


def _walk(T: int = 60) -> np.ndarray:
    """The humanoid marching with knee lifts while moving forward at 1 m/s (metres, Y-up, 20 fps)."""
    pytest.importorskip("mujoco")
    from simdiff.sim import synthetic

    j = np.asarray(synthetic.walk_in_place(T), dtype=np.float64)
    j[:, :, 2] += np.arange(T)[:, None] / 20.0
    return j


def test_pose_mask_keeps_horizontal_pose_and_rotations_only() -> None:
    m = pose_feature_mask()
    assert m.sum() == 42 + 126
    assert not m[:4].any() and not m[193:].any()  # root channels, velocities, contacts
    assert m[4] and not m[5] and m[6]  # ric x, (not y), z of joint 1


def test_retimed_and_raised_rollout_is_faithful_a_different_pose_is_not() -> None:
    norm = Normalizer(np.zeros(263, dtype=np.float32), np.full(263, 0.05, dtype=np.float32))
    src = _walk()
    # the rollout waits 20 frames at frame 30 (a long flight) and rises by up to 0.4 m there
    idx = np.concatenate([np.arange(30), np.full(20, 30), np.arange(31, 60)])
    out = src[idx].copy()
    out[30:50, :, 1] += 0.4 * np.sin(np.linspace(0, np.pi, 20))[:, None]
    # the clock's reference frame (30 Hz) at every control step of the rollout
    control = np.interp(np.arange(int(len(idx) * 1.5)) / 30.0, np.arange(len(idx)) / 20.0, idx / 20.0) * 30.0
    aligned = aligned_source(src, control, 30.0, 20.0, len(out))
    assert np.allclose(aligned[:30], src[:30], atol=1e-4)
    faithful = pose_d_l2(aligned, out, norm)
    unaligned = pose_d_l2(src, out, norm)
    from simdiff.sim import synthetic

    other = np.asarray(synthetic.squat(len(out), depth=0.6), dtype=np.float64)  # another motion, same path
    other[:, :, 2] += out[:, :1, 2] - other[:, :1, 2]
    unfaithful = pose_d_l2(aligned, other, norm)
    assert faithful < 0.5 * unaligned
    from simdiff.sim.project import d_l2

    assert d_l2(aligned, out, norm) > 10 * faithful  # the paper's d_L2 punishes the height and speed change
    assert unfaithful > 3 * faithful
    assert np.isnan(pose_d_l2(aligned, out, None)) and np.isnan(pose_d_l2(aligned[:1], out[:1], norm))
