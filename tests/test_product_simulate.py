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
    """A still stand (the humanoid's rest pose; ``walk(speed=0, amplitude=0)`` is not one: its shins
    kick back at up to 1.6 m/s and its feet dip 13 mm into the floor) under weak gravity and wind."""
    from simdiff.sim.synthetic import standing as still_stand

    standing = still_stand(30).astype(np.float32)
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


def test_simulated_motion_shares_the_floor_of_humanml3d() -> None:
    """A flat planted foot's toe joint is on y = 0 (within the metrics' 5 mm contact slack), as in
    HumanML3D, so the simulated motion's sliding is measured on real contacts, not vacuously 0."""
    from simdiff.motion.metrics import GROUND_TOLERANCE

    from simdiff.sim.synthetic import standing

    still = standing(30)
    still[..., 1] -= still[..., 1].min()  # HumanML3D's floor: the lowest joint on y = 0
    sim = simulate_finish(still, Environment())
    assert sim.tracking["status"] == "ok"
    lowest = sim.joints[..., 1].min(axis=1)
    assert np.all(np.abs(lowest) <= GROUND_TOLERANCE), lowest
    assert sim.tracking["physics_simulated"]["floating"] <= 1.0


def test_toe_joint_height_is_the_models_own() -> None:
    """TOE_JOINT_HEIGHT is what the MuJoCo body has: toe joint above the lowest corner of its sole, flat."""
    import mujoco

    from simdiff.sim.humanoid import TOE_JOINT_HEIGHT, HumanoidConfig, load_model
    from simdiff.sim.retarget.kinematics import box_bottom_corners, foot_geoms

    model = load_model(HumanoidConfig())
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    for name, geom in zip(("L_Toe", "R_Toe"), foot_geoms(model)[1::2]):
        body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, name)
        height = data.xpos[body][2] - box_bottom_corners(model, data, geom)[:, 2].min()
        assert height == pytest.approx(TOE_JOINT_HEIGHT, abs=1e-6)


def test_a_stand_gliding_on_planted_feet_is_simulated_standing_still() -> None:
    """Generated motion often glides on planted feet; the finish anchors them (the body does not
    travel without steps) and its feet do not slide; the tracking result says so."""
    from simdiff.sim.retarget.contacts import ANCHOR_VERSION
    from simdiff.sim.synthetic import standing

    glide = standing(40)
    glide[..., 1] -= glide[..., 1].min()
    glide[..., 0] += 0.01 * np.arange(40)[:, None]  # 1 cm/frame, feet included
    sim = simulate_finish(glide, Environment())
    t = sim.tracking
    assert t["status"] == "ok" and t["anchor_stance"] and t["anchor_version"] == ANCHOR_VERSION
    assert t["physics_generated"]["sliding"] > 5.0
    assert t["physics_simulated"]["sliding"] <= 0.1  # measured 0.008 (0.45 unanchored, gliding 0.36 m)
    # a glide 2 cm above the floor: CLoSD's sliding cannot see it, the own-floor sliding can
    hover = glide.copy()
    hover[..., 1] += 0.02
    t = simulate_finish(hover, Environment()).tracking
    assert t["physics_generated"]["sliding"] == 0.0 and t["physics_generated"]["sliding_own_floor"] > 5.0
    assert abs(t["physics_generated"]["own_floor"] - 20.0) < 1.0
    assert t["physics_simulated"]["sliding_own_floor"] <= 0.5
    assert abs(float(sim.joints[-1, 0, 0] - sim.joints[0, 0, 0])) < 0.03  # stood still instead of gliding 0.39 m
