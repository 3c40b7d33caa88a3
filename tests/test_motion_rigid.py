"""simdiff.motion.rigid's smoothing: the Gaussian low-pass equals scipy's, and the written joints are smoothed."""

from __future__ import annotations

import numpy as np
import pytest

from simdiff.motion.rigid import gaussian_filter_frames, smooth_positions


@pytest.mark.parametrize("frames", [1, 2, 5, 196])
@pytest.mark.parametrize("sigma", [1.0, 1.5, 3.0])
def test_gaussian_filter_equals_scipy_nearest(frames: int, sigma: float) -> None:
    ndimage = pytest.importorskip("scipy.ndimage")
    x = np.random.default_rng(frames).normal(size=(frames, 22, 3))
    expected = ndimage.gaussian_filter1d(x, sigma, axis=0, mode="nearest")
    assert np.allclose(gaussian_filter_frames(x, sigma), expected, rtol=0, atol=1e-12)


def test_smoothing_keeps_a_steady_motion_and_damps_a_one_frame_spike() -> None:
    t = np.arange(60, dtype=np.float64)
    joints = np.zeros((60, 22, 3))
    joints[..., 2] = 0.05 * t[:, None]  # walking forward at 1 m/s
    joints[:, 1:, 1] = np.linspace(0.1, 1.6, 21)
    assert np.allclose(smooth_positions(joints)[8:-8], joints[8:-8], atol=1e-12)  # linear paths pass (ends held)
    spiked = joints.copy()
    spiked[30, 10, 0] += 0.3
    assert abs(smooth_positions(spiked)[30, 10, 0]) < 0.3 * 0.45  # σ 1 frame keeps 40 % of a lone spike
