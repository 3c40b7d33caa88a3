"""Ground clean-ups of retargeted joints: floor-tilt levelling and the CMU unit detection."""

from __future__ import annotations

import numpy as np
import pytest

from simdiff.motion.io.bvh import KNOWN_SCALES, detect_scale, rig_height
from simdiff.motion.io.ground import ground_slope, level_ground


def _walk(slope: float, length: float = 4.0, frames: int = 100) -> np.ndarray:
    """(T, 22, 3) stick body walking along +X with its feet on a floor y = slope * x."""
    rng = np.random.default_rng(0)
    x = np.linspace(0.0, length, frames)
    joints = np.zeros((frames, 22, 3))
    joints[:, :, 0] = x[:, None]
    joints[:, :, 1] = np.linspace(0.0, 1.6, 22)[None] + slope * x[:, None]
    joints[:, :, 2] = rng.normal(0.0, 0.1, size=22)[None]
    # swing foot: every other half second one foot joint lifts 5 cm
    lift = 0.05 * (np.sin(np.arange(frames) * np.pi / 10) > 0)
    joints[:, 1, 1] += lift
    return joints


def test_level_ground_removes_a_small_tilt() -> None:
    joints = _walk(0.02)
    u, slope, spread, travel = ground_slope(joints)
    assert abs(slope) == pytest.approx(0.02, abs=1e-3) and travel == pytest.approx(4.0, abs=0.01)
    out = level_ground(joints)
    lowest = out[..., 1].min(axis=-1)
    assert lowest.max() < 1e-4  # every frame stands on the floor after levelling
    assert np.ptp(joints[..., 1].min(axis=-1)) > 0.07  # (it rose 8 cm before)
    assert out.dtype == np.float32


@pytest.mark.parametrize("slope, length", [(0.10, 4.0), (0.02, 0.5), (0.002, 4.0)])
def test_level_ground_leaves_ramps_short_clips_and_flat_floors(slope: float, length: float) -> None:
    joints = _walk(slope, length)
    out = level_ground(joints)
    expected = joints.copy()
    expected[..., 1] -= expected[..., 1].min()
    np.testing.assert_allclose(out, expected, atol=1e-5)


def test_cmu_unit_is_detected() -> None:
    assert KNOWN_SCALES["cmu"] == pytest.approx(0.0254 / 0.45)
    assert detect_scale(30.0) == KNOWN_SCALES["cmu"]  # a 1.7 m body in inch/0.45 units
    assert detect_scale(68.0) == KNOWN_SCALES["inch"]
    # body size: a high percentile, so a clip spent crouching still sees the standing body
    crouch = np.zeros((100, 2, 3))
    crouch[:, 1, 1] = 100.0  # cm
    crouch[:15, 1, 1] = 170.0
    assert rig_height(crouch) == pytest.approx(170.0)
    assert detect_scale(rig_height(crouch)) == 0.01
