"""Resampling motion arrays to 20 fps with anti-aliasing."""

from __future__ import annotations

import numpy as np
import pytest

from simdiff.motion.io.resample import resample


def _sine(fps: float, seconds: float, hz: float, phase: float = 0.3) -> np.ndarray:
    t = np.arange(int(round(seconds * fps))) / fps
    return np.sin(2 * np.pi * hz * t + phase)[:, None, None] * np.ones((1, 2, 3))


@pytest.mark.parametrize("src", [120.0, 60.0, 30.0])
def test_slow_signal_is_kept(src: float) -> None:
    x = _sine(src, 6.0, 1.0)
    y = resample(x, src, 20.0)
    assert y.dtype == np.float32
    assert y.shape == (120, 2, 3)
    t = np.arange(120) / 20.0
    expected = np.sin(2 * np.pi * t + 0.3)
    assert np.abs(y[:, 0, 0] - expected).max() < 0.005  # ends included: no droop


def test_frequencies_above_target_nyquist_are_removed() -> None:
    # 12 Hz cannot be represented at 20 fps: plain decimation would alias it to 8 Hz
    x = _sine(30.0, 10.0, 12.0)
    y = resample(x, 30.0, 20.0)
    assert y.shape[0] == 200
    assert np.abs(y[20:-20]).max() < 0.01
    assert np.abs(x[::3]).max() > 0.5  # naive decimation would have kept it


def test_linear_motion_exact_and_length() -> None:
    t = np.arange(343) / 120.0
    x = np.stack([t * 1.5, 0.9 + 0 * t, -2 * t], axis=-1)[:, None, :]
    y = resample(x, 120.0, 20.0)
    assert y.shape == (58, 1, 3)  # ceil(343 / 6)
    t20 = np.arange(58) / 20.0
    np.testing.assert_allclose(y[:, 0, 0], t20 * 1.5, atol=1e-5)
    np.testing.assert_allclose(y[:, 0, 2], -2 * t20, atol=1e-5)


def test_awkward_ratio_uses_filtered_interpolation() -> None:
    x = _sine(47.3, 4.0, 0.5)
    y = resample(x, 47.3, 20.0)
    n = int(np.ceil(x.shape[0] * 20.0 / 47.3))
    assert y.shape == (n, 2, 3)
    t = np.arange(n) / 20.0
    assert np.abs(y[:, 1, 2] - np.sin(2 * np.pi * 0.5 * t + 0.3)).max() < 0.01


def test_same_rate_and_short_inputs() -> None:
    x = np.arange(12, dtype=np.float64).reshape(2, 2, 3)
    np.testing.assert_array_equal(resample(x, 20.0, 20.0), x.astype(np.float32))
    one = resample(x[:1], 60.0, 20.0)
    assert one.shape == (1, 2, 3)
    with pytest.raises(ValueError):
        resample(x, 0.0, 20.0)
