"""Environment φ validation and how it is written into the model."""

from __future__ import annotations

import numpy as np
import pytest

from simdiff.errors import SimdiffError
from simdiff.sim.env import Environment


@pytest.mark.parametrize("phi", [(-9.81, 0, 0), (-20, 0, 0), (-1, 0, 0), (-3, 10, 0), (-9.81, 6, -8)])
def test_valid(phi):
    assert Environment(*phi).validate() is not None


@pytest.mark.parametrize(
    "phi, word",
    [((-25, 0, 0), "gravity"), ((-0.5, 0, 0), "gravity"), ((-9.81, 8, 8), "wind"), ((3.0, 0, 0), "negative"),
     ((float("nan"), 0, 0), "finite")],
)
def test_invalid(phi, word):
    with pytest.raises(SimdiffError, match=word):
        Environment(*phi).validate()


def test_force_allows_out_of_range_but_not_positive_gravity():
    Environment(-30.0, 20.0, 0.0).validate(force=True)
    with pytest.raises(SimdiffError):
        Environment(1.0).validate(force=True)


def test_apply_gravity_and_mass_distributed_wind():
    mujoco = pytest.importorskip("mujoco")
    from simdiff.sim.humanoid import load_model

    import copy

    m = copy.copy(load_model())
    env = Environment(-3.0, 10.0, -5.0)
    env.apply(m)
    mass = float(m.body_subtreemass[1])
    assert m.opt.gravity[2] == -3.0
    # total horizontal force on the body is the wind, in world coords (x = HML z, y = HML x)
    assert np.allclose(m.opt.gravity[:2] * mass, [-5.0, 10.0])
    assert np.allclose(env.wind_world, [-5.0, 10.0, 0.0])
    assert m.opt.density == 0 and m.opt.viscosity == 0
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    # qfrc_bias of the root's linear rows is −Σ m_i g (no velocity): equals −(wind + weight)
    assert np.allclose(-d.qfrc_bias[:3], [-5.0, 10.0, -3.0 * mass], atol=1e-6)
