"""The shipped model's output does not drift: fixed ``simdiff generate`` calls reproduce stored joints.

``tests/data/generate_golden.npz`` holds the (60, 22, 3) joint positions (metres) of the features the shipped model
wrote for the calls below (60 frames, default sampling settings). A refactor that changes sampling, guidance, the
foot cleanup or the model loading changes them. The joints file written beside them is those positions fitted on a
rigid skeleton (:func:`simdiff.motion.rigid.joints_from_features`).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from simdiff.cli.main import main
from simdiff.motion.features import features_to_joints
from simdiff.motion.rigid import bone_lengths, joints_from_features

GOLDEN = Path(__file__).parent / "data" / "generate_golden.npz"
CALLS: dict[str, list[str]] = {
    "earth_s0": ["a person jumps forward", "--seed", "0"],
    "earth_s1": ["a person jumps forward", "--seed", "1"],
    "moon_s0": ["a person jumps forward", "--seed", "0", "--gravity", "-1.6"],
    "wind_s0": ["a person walks forward", "--seed", "0", "--wind", "10", "0"],
    "mars_wind_s1": ["a person walks forward", "--seed", "1", "--gravity", "-3.7", "--wind", "5", "-5"],
}
TOLERANCE_M = 1e-5


@pytest.mark.parametrize("name", sorted(CALLS))
def test_generate_reproduces_stored_joints(name: str, tmp_path: Path) -> None:
    out = tmp_path / name
    code = main(["generate", *CALLS[name], "--length", "3", "--format", "npy", "--out", str(out), "-q"])
    assert code == 0
    features = np.load(out / "sample0_features.npy")
    positions = np.asarray(features_to_joints(features))
    expected = np.load(GOLDEN)[name]
    assert positions.shape == expected.shape == (60, 22, 3)
    assert float(np.abs(positions - expected).max()) <= TOLERANCE_M
    joints = np.load(out / "sample0_joints.npy")
    np.testing.assert_array_equal(joints, joints_from_features(features))
    assert float(np.ptp(bone_lengths(joints), axis=0).max()) <= 1e-5
