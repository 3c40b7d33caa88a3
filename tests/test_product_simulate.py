"""The simulated finish (``simdiff generate --simulate``) on a short synthetic motion, in the real simulator."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from simdiff.errors import SimdiffError
from simdiff.motion.synthetic import walk
from simdiff.product.simulate import simulate_finish, write_simulated
from simdiff.sim.env import Environment


def _finite(value) -> bool:
    if isinstance(value, dict):
        return all(_finite(v) for v in value.values())
    if isinstance(value, list):
        return all(_finite(v) for v in value)
    return not isinstance(value, float) or math.isfinite(value)


def test_standing_motion_is_tracked_without_sliding(tmp_path: Path) -> None:
    standing = walk(30, speed=0.0, amplitude=0.0, bounce=0.0)
    sim = simulate_finish(standing, Environment(-3.7, 2.0, 0.0))
    t = sim.tracking
    assert t["status"] == "ok" and t["success"] and t["env"] == [-3.7, 2.0, 0.0] and not t["env_assumed"]
    assert sim.joints.dtype == np.float32 and sim.joints.shape[1:] == (22, 3) and len(sim.joints) == t["n_out"] >= 30
    assert t["physics_simulated"]["sliding"] <= 0.5 and t["physics_simulated"]["penetration"] <= 1.0
    assert t["d_l2"] is None and _finite(t)  # no normaliser given: d_L2 null, never NaN in JSON
    written = write_simulated(tmp_path / "sample0", sim, ["npy", "bvh"])
    assert {p.name for p in written.values()} == {"sample0_simulated_joints.npy", "sample0_simulated.bvh",
                                                  "sample0_tracking.json"}
    np.testing.assert_array_equal(np.load(written["simulated_joints"]), sim.joints)
    assert json.loads(written["tracking"].read_text())["status"] == "ok"


def test_backbone_motion_is_simulated_under_earth_and_bad_shapes_fail() -> None:
    sim = simulate_finish(walk(6, speed=0.0, amplitude=0.0, bounce=0.0), None)
    assert sim.tracking["env"] == [-9.81, 0.0, 0.0] and sim.tracking["env_assumed"]
    with pytest.raises(SimdiffError, match=r"\(T>=2, 22, 3\)"):
        simulate_finish(np.zeros((1, 22, 3)), None)
