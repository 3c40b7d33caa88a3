"""Tests for simdiff.motion.normalize."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import torch

from simdiff.errors import SimdiffError
from simdiff.motion.normalize import FEATURE_GROUPS, Normalizer, group_std


def _normalizer() -> Normalizer:
    mean = np.linspace(-1.0, 1.0, 263).astype(np.float32)
    std = np.linspace(0.5, 2.0, 263).astype(np.float32)
    return Normalizer(mean, std)


def test_shipped_std_is_grouped(shared_data: Path) -> None:
    norm = Normalizer.from_dir(shared_data / "humanml3d")
    assert norm.std.dtype == np.float32 and norm.std.shape == (263,)
    for start, stop in FEATURE_GROUPS:
        group = norm.std[start:stop]
        np.testing.assert_array_equal(group, np.full_like(group, group[0]))
    # Group values from the facts sheet.
    expected = [0.012826, 0.016927, 0.153766, 0.122244, 0.299692, 0.019470, 0.355933]
    got = [norm.std[start] for start, _ in FEATURE_GROUPS]
    np.testing.assert_allclose(got, expected, atol=2e-6)
    assert norm.mean[3] == pytest.approx(0.9386, abs=1e-4)


def test_group_std_on_synthetic_clips() -> None:
    rng = np.random.default_rng(0)
    scales = rng.uniform(0.1, 3.0, size=263)
    clips = [rng.normal(2.0, 1.0, size=(n, 263)) * scales for n in (50, 70, 30)]
    mean, std = group_std(clips)
    allrows = np.concatenate(clips)
    np.testing.assert_allclose(mean, allrows.mean(axis=0), rtol=1e-6, atol=1e-6)
    raw = allrows.std(axis=0)  # population std, ddof=0
    for start, stop in FEATURE_GROUPS:
        np.testing.assert_allclose(std[start:stop], raw[start:stop].mean(), rtol=1e-6)
    assert mean.dtype == np.float32 and std.dtype == np.float32


def test_group_std_hand_values() -> None:
    # Two frames: channel c takes values (0, 2c) -> std = c; ric group [4:67] averages 4..66.
    x = np.zeros((2, 263))
    x[1] = 2.0 * np.arange(263)
    mean, std = group_std(x)
    assert mean[10] == pytest.approx(10.0)
    assert std[0] == pytest.approx(0.0)
    assert std[1] == pytest.approx(1.5) and std[2] == pytest.approx(1.5)
    assert std[3] == pytest.approx(3.0)
    assert std[4] == pytest.approx(35.0) and std[66] == pytest.approx(35.0)
    assert std[67] == pytest.approx(129.5)
    assert std[193] == pytest.approx(225.5)
    assert std[262] == pytest.approx(260.5)


def test_group_std_skips_nan_clips() -> None:
    good = np.ones((3, 263))
    bad = np.full((3, 263), np.nan)
    with pytest.warns(UserWarning, match="features\\[1\\]"):
        mean, _ = group_std([good, bad])
    np.testing.assert_array_equal(mean, np.ones(263, dtype=np.float32))


def test_roundtrip_numpy_and_torch_any_leading_dims() -> None:
    norm = _normalizer()
    x = np.random.default_rng(1).normal(size=(2, 5, 263)).astype(np.float32)
    z = norm.normalize(x)
    assert isinstance(z, np.ndarray) and z.dtype == np.float32
    assert z[1, 2, 0] == pytest.approx((x[1, 2, 0] + 1.0) / 0.5)
    np.testing.assert_allclose(norm.denormalize(z), x, atol=1e-5)
    t = torch.from_numpy(x)
    zt = norm.normalize(t)
    assert isinstance(zt, torch.Tensor) and zt.dtype == torch.float32
    np.testing.assert_allclose(zt.numpy(), z, atol=1e-6)
    np.testing.assert_allclose(norm.denormalize(zt).numpy(), x, atol=1e-5)
    zt64 = norm.normalize(t.double())
    assert zt64.dtype == torch.float64


def test_save_and_from_dir(tmp_path: Path) -> None:
    norm = _normalizer()
    norm.save(tmp_path)
    again = Normalizer.from_dir(tmp_path)
    np.testing.assert_array_equal(again.mean, norm.mean)
    np.testing.assert_array_equal(again.std, norm.std)


def test_clear_errors(tmp_path: Path) -> None:
    with pytest.raises(SimdiffError, match="Mean.npy"):
        Normalizer.from_dir(tmp_path)
    np.save(tmp_path / "Mean.npy", np.zeros(263, np.float32))
    np.save(tmp_path / "Std.npy", np.ones(251, np.float32))
    with pytest.raises(SimdiffError, match=r"\(251,\)"):
        Normalizer.from_dir(tmp_path)
    with pytest.raises(SimdiffError, match="not found"):
        Normalizer.from_dir(tmp_path / "missing")
    with pytest.raises(SimdiffError, match=r"std\[5\]=0"):
        Normalizer(np.zeros(263), np.where(np.arange(263) == 5, 0.0, 1.0))
    with pytest.raises(SimdiffError, match="263 channels"):
        _normalizer().normalize(np.zeros((4, 251)))


def test_shipped_default_statistics_are_grouped_and_plausible():
    from simdiff.motion.normalize import default_normalizer

    norm = default_normalizer()
    assert norm.mean.shape == norm.std.shape == (263,)
    assert 0.8 < norm.mean[3] < 1.0  # root height of standing people, metres
    for group in (slice(4, 67), slice(67, 193), slice(193, 259), slice(259, 263)):
        assert np.ptp(norm.std[group]) == 0.0  # HumanML3D-style group-averaged std
