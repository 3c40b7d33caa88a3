"""The one scalar-first ⇄ scalar-last helper pair, checked against scipy and MuJoCo."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from simdiff.motion.quaternion import quat_to_matrix, wxyz_to_xyzw, xyzw_to_wxyz


def _random_wxyz(n: int) -> np.ndarray:
    q = np.random.default_rng(3).normal(size=(n, 4))
    return q / np.linalg.norm(q, axis=1, keepdims=True)


def test_scipy_reads_our_order_as_the_same_rotation():
    q = _random_wxyz(16)
    assert np.allclose(Rotation.from_quat(wxyz_to_xyzw(q)).as_matrix(), quat_to_matrix(q), atol=1e-12)
    back = xyzw_to_wxyz(Rotation.from_matrix(quat_to_matrix(q)).as_quat())
    assert np.allclose(np.abs(np.sum(back * q, axis=1)), 1.0)  # same rotation (q or -q)


def test_round_trip_and_leading_dimensions():
    q = _random_wxyz(6).reshape(2, 3, 4)
    assert np.array_equal(xyzw_to_wxyz(wxyz_to_xyzw(q)), q)
    assert wxyz_to_xyzw(q).shape == (2, 3, 4)
    assert np.array_equal(wxyz_to_xyzw(np.array([1.0, 2.0, 3.0, 4.0])), [2.0, 3.0, 4.0, 1.0])


def test_mujoco_agrees_with_scipy_through_the_helper():
    mujoco = pytest.importorskip("mujoco")
    for q in _random_wxyz(4):
        mat = np.zeros(9)
        mujoco.mju_quat2Mat(mat, q)  # MuJoCo quaternions are (w, x, y, z)
        assert np.allclose(mat.reshape(3, 3), Rotation.from_quat(wxyz_to_xyzw(q)).as_matrix(), atol=1e-12)
