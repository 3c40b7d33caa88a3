"""The shipped model's output does not drift: fixed ``simdiff generate`` calls reproduce stored joints.

``tests/data/generate_golden.npz`` holds the (60, 22, 3) joints (metres) the shipped model wrote for the calls below
(60 frames, default sampling settings): the features' positions fitted on a rigid skeleton, planted feet held
(:func:`simdiff.motion.rigid.joints_from_features`). A change to sampling, guidance, the foot cleanup, the rigid fit
or the model loading changes them; after a deliberate one, ``SIMDIFF_WRITE_GOLDEN=1 pytest
tests/test_generate_golden.py`` rewrites the file (then look at the motions before committing it).
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

from simdiff.cli.main import main
from simdiff.inference.default import sampling_config
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
    joints = np.load(out / "sample0_joints.npy")
    np.testing.assert_array_equal(joints, joints_from_features(features, sampling_config().foot_lock))
    assert float(np.ptp(bone_lengths(joints), axis=0).max()) <= 1e-5
    if os.environ.get("SIMDIFF_WRITE_GOLDEN"):
        stored = dict(np.load(GOLDEN)) if GOLDEN.is_file() else {}
        np.savez(GOLDEN, **{**stored, name: joints})
    expected = np.load(GOLDEN)[name]
    assert joints.shape == expected.shape == (60, 22, 3)
    assert float(np.abs(joints - expected).max()) <= TOLERANCE_M
