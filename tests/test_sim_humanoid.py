"""The generated MJCF: structure, masses, symmetry, standing rest pose."""

from __future__ import annotations

import numpy as np
import pytest

mujoco = pytest.importorskip("mujoco")

from simdiff.sim.humanoid import (  # noqa: E402
    BODY_NAMES,
    HumanoidConfig,
    build_mjcf,
    hml_to_world,
    load_model,
    model_index,
    world_to_hml,
)


def test_structure():
    m = load_model()
    assert (m.nq, m.nv, m.nu, m.njnt) == (76, 75, 69, 70)
    assert m.nbody == 25
    assert [mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, i + 1) for i in range(24)] == list(BODY_NAMES)
    assert m.opt.timestep == pytest.approx(1 / 450)
    assert m.opt.integrator == mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    assert m.jnt_type[0] == mujoco.mjtJoint.mjJNT_FREE
    assert np.all(m.jnt_type[1:] == mujoco.mjtJoint.mjJNT_HINGE)
    assert np.all(m.actuator_trnid[:, 0] >= 1)  # nothing actuates the root
    assert "<mujoco" in build_mjcf(HumanoidConfig())


def test_mass_and_symmetry():
    m = load_model()
    ix = model_index(m)
    assert 68 < ix.mass < 76
    names = [mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, i) for i in range(1, m.njnt)]
    for i, n in enumerate(names):
        if n.startswith("L_"):
            j = names.index("R_" + n[2:])
            assert ix.kp[i] == ix.kp[j] and ix.kd[i] == ix.kd[j] and ix.fmax[i] == ix.fmax[j]
            lo, hi = m.jnt_range[i + 1]
            rlo, rhi = m.jnt_range[j + 1]
            if n.endswith("_y"):
                assert (lo, hi) == pytest.approx((rlo, rhi))
            else:  # x and z rotations flip under the left/right mirror
                assert (lo, hi) == pytest.approx((-rhi, -rlo))
    bid = {n: mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, n) for n in BODY_NAMES}
    assert m.body_mass[bid["L_Hip"]] == m.body_mass[bid["R_Hip"]]


def test_rest_pose_stands_on_flat_feet():
    m = load_model()
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    ix = model_index(m)
    lowest = []
    for g in ix.foot_geoms:
        size = m.geom_size[g]
        corners = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]) * size
        world = d.geom_xpos[g] + corners @ d.geom_xmat[g].reshape(3, 3).T
        lowest.append(world[:, 2].min())
    assert np.allclose(lowest, 0.0, atol=2e-3)
    for _ in range(450):  # holding the rest pose for 1 s: stays up
        mujoco.mj_step(m, d)
    assert d.xpos[ix.head, 2] > 1.4


def test_frame_conversion_roundtrip():
    p = np.random.default_rng(0).normal(size=(5, 22, 3))
    assert np.allclose(world_to_hml(hml_to_world(p)), p)
    assert np.allclose(hml_to_world(np.array([0.0, 1.0, 0.0])), [0, 0, 1])  # Y-up -> Z-up
    assert np.allclose(hml_to_world(np.array([0.0, 0.0, 1.0])), [1, 0, 0])  # facing +Z -> +x
