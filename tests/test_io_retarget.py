"""Retargeting to the HumanML3D 22-joint skeleton and the load_joints dispatcher."""

from __future__ import annotations

import importlib.util
import json
import tarfile
from pathlib import Path

import numpy as np
import pytest

from simdiff.errors import MotionFormatError
from simdiff.motion.io import RigMotion, load_joints, write_bvh
from simdiff.motion.io.retarget import (
    CC_BVH_MAP,
    CMU_ASF_MAP,
    DEEPMIMIC_MAP,
    map_joints,
    retarget_rig,
    to_canonical_lengths,
)
from simdiff.motion.skeleton import BONE_LENGTHS, CANONICAL_OFFSETS, JOINT_NAMES, PARENTS

CMU_BONES = (
    "root", "lhipjoint", "rhipjoint", "lowerback", "lfemur", "rfemur", "upperback", "ltibia",
    "rtibia", "thorax", "lfoot", "rfoot", "lowerneck", "lclavicle", "rclavicle", "ltoes",
    "rtoes", "upperneck", "lhumerus", "rhumerus", "head", "lradius", "rradius", "lwrist",
    "rwrist", "head_centre", "lshoulder_centre", "rshoulder_centre",
)
"""CMU ASF bone ends plus the AMC reader's derived sites."""


def _cmu_rig(num_frames: int, fps: float) -> RigMotion:
    rng = np.random.default_rng(1)
    pos = rng.normal(size=(num_frames, len(CMU_BONES), 3))
    return RigMotion(CMU_BONES, (-1,) + (0,) * (len(CMU_BONES) - 1), pos, fps)


def test_cmu_map_picks_and_interpolates() -> None:
    rig = _cmu_rig(4, 120.0)
    out = map_joints(rig)
    p = {name: rig.positions[:, i].astype(np.float64) for i, name in enumerate(CMU_BONES)}
    np.testing.assert_allclose(out[:, 7], p["ltibia"], atol=1e-6)
    # pelvis 15 % of the way from the hip centre to the neck base
    hips = 0.5 * (p["lhipjoint"] + p["rhipjoint"])
    np.testing.assert_allclose(out[:, 0], 0.85 * hips + 0.15 * p["lowerneck"], atol=1e-6)
    np.testing.assert_allclose(out[:, JOINT_NAMES.index("spine3")], 0.8 * p["upperback"] + 0.2 * p["thorax"], atol=1e-6)
    collar = 0.55 * p["thorax"] + 0.45 * p["lshoulder_centre"]
    np.testing.assert_allclose(out[:, JOINT_NAMES.index("left_collar")], collar, atol=1e-6)
    np.testing.assert_allclose(out[:, JOINT_NAMES.index("head")], p["head_centre"], atol=1e-6)
    assert set(CMU_ASF_MAP) == set(JOINT_NAMES)


def test_map_weights_sum_to_one() -> None:
    """Every map entry is an affine combination: it moves rigidly with the body."""
    from simdiff.motion.io.retarget import _terms

    from simdiff.motion.io.rigs import RIGS

    for joint_map in (CMU_ASF_MAP, CC_BVH_MAP, DEEPMIMIC_MAP, *(spec.joint_map for spec in RIGS)):
        for name, src in joint_map.items():
            assert sum(w for _, w in _terms(src)) == pytest.approx(1.0, abs=1e-9), name
        assert set(joint_map) >= set(JOINT_NAMES) - {"left_foot", "right_foot"}


def test_rig_families_are_told_apart() -> None:
    """Each family's joint names select that family (no earlier family claims them)."""
    from simdiff.motion.io.rigs import RIGS, detect_rig

    for spec in RIGS:
        names = tuple(sorted(spec.needs()))
        assert detect_rig(names) is spec, spec.name


def test_cc_map_is_translation_and_rotation_equivariant() -> None:
    names = sorted({n for src in CC_BVH_MAP.values() for n, _ in __import__(
        "simdiff.motion.io.retarget", fromlist=["_terms"])._terms(src)})
    rng = np.random.default_rng(3)
    pos = rng.normal(size=(3, len(names), 3))
    rig = RigMotion(tuple(names), (-1,) + (0,) * (len(names) - 1), pos, 60.0)
    c, s_ = np.cos(0.7), np.sin(0.7)
    rot = np.array([[c, 0, s_], [0, 1, 0], [-s_, 0, c]])
    moved = RigMotion(rig.names, rig.parents, pos @ rot.T + np.array([1.0, 2.0, 3.0]), 60.0)
    np.testing.assert_allclose(map_joints(moved), map_joints(rig) @ rot.T + np.array([1.0, 2.0, 3.0]), atol=1e-5)


def test_package_names_are_modules() -> None:
    """``simdiff.motion.io.retarget`` / ``.resample`` are the modules, never the functions."""
    import types

    import simdiff.motion.io as io_pkg
    import simdiff.motion.io.resample  # noqa: F401
    import simdiff.motion.io.retarget  # noqa: F401

    assert isinstance(io_pkg.retarget, types.ModuleType)
    assert isinstance(io_pkg.resample, types.ModuleType)
    assert callable(io_pkg.retarget_rig) and io_pkg.retarget.retarget_rig is io_pkg.retarget_rig
    assert callable(io_pkg.resample.resample)


def test_retarget_resamples_and_floors() -> None:
    rig = _cmu_rig(240, 120.0)
    out = retarget_rig(rig)
    assert out.shape == (40, 22, 3) and out.dtype == np.float32
    assert out[..., 1].min() == pytest.approx(0.0, abs=1e-6)


def test_unknown_rig_is_a_format_error() -> None:
    rig = RigMotion(("a", "b"), (-1, 0), np.zeros((3, 2, 3)), 30.0, Path("odd.bvh"))
    with pytest.raises(MotionFormatError, match=r"odd\.bvh: no HumanML3D joint map"):
        retarget_rig(rig)


def test_biped_names(tmp_path: Path) -> None:
    names = (
        "mixamorig:Hips", "mixamorig:LeftUpLeg", "mixamorig:RightUpLeg", "mixamorig:Spine",
        "mixamorig:LeftLeg", "mixamorig:RightLeg", "mixamorig:LeftFoot", "mixamorig:RightFoot",
        "mixamorig:LeftToeBase", "mixamorig:RightToeBase", "mixamorig:Neck", "mixamorig:Head",
        "mixamorig:LeftArm", "mixamorig:RightArm", "mixamorig:LeftForeArm",
        "mixamorig:RightForeArm", "mixamorig:LeftHand", "mixamorig:RightHand",
    )
    pos = np.arange(2 * len(names) * 3, dtype=np.float64).reshape(2, len(names), 3)
    out = map_joints(RigMotion(names, (-1,) + (0,) * (len(names) - 1), pos, 30.0))
    np.testing.assert_allclose(out[:, JOINT_NAMES.index("left_knee")], pos[:, 4])
    np.testing.assert_allclose(out[:, JOINT_NAMES.index("spine1")], pos[:, 3])
    # no Spine1/Spine2: spine2 half way from the hips to the neck
    np.testing.assert_allclose(out[:, JOINT_NAMES.index("spine2")], 0.5 * (pos[:, 0] + pos[:, 10]))


def test_toes_derived_when_missing() -> None:
    names = ("Hips", "LeftUpLeg", "RightUpLeg", "LeftLeg", "RightLeg", "LeftFoot", "RightFoot",
             "Neck", "Head", "LeftArm", "RightArm", "LeftForeArm", "RightForeArm", "LeftHand",
             "RightHand")
    pos = np.zeros((1, len(names), 3))
    pos[0, :7] = [[0, 1, 0], [0.1, 0.9, 0], [-0.1, 0.9, 0], [0.1, 0.5, 0], [-0.1, 0.5, 0],
                  [0.1, 0.07, 0], [-0.1, 0.07, 0]]
    out = map_joints(RigMotion(names, (-1,) + (0,) * (len(names) - 1), pos, 30.0))
    # left is +X, so the body faces +Z: toes 0.33 x 0.43 m ahead, 0.12 x 0.43 m lower
    np.testing.assert_allclose(out[0, 10], [0.1, 0.07 - 0.0516, 0.1419], atol=1e-6)
    np.testing.assert_allclose(out[0, 11], [-0.1, 0.07 - 0.0516, 0.1419], atol=1e-6)


def _deepmimic_file(tmp_path: Path, num_frames: int = 30) -> Path:
    q = [1.0, 0.0, 0.0, 0.0]
    frames = []
    for k in range(num_frames):
        root = [0.05 * k, 0.9, 0.0]
        frames.append([1 / 30, *root, *q, *q, *q, *q, -0.3, *q, *q, 0.2, *q, -0.3, *q, *q, 0.2])
    path = tmp_path / "walk.txt"
    path.write_text(json.dumps({"Loop": "none", "Frames": frames}))
    return path


def test_deepmimic_orientation(tmp_path: Path) -> None:
    joints = load_joints(_deepmimic_file(tmp_path)).astype(np.float64)
    assert joints.shape == (20, 22, 3)  # 30 frames at 30 fps -> 20 at 20 fps
    assert joints[..., 1].min() == pytest.approx(0.0, abs=1e-6)
    up = np.array([0.0, 1.0, 0.0])
    left = joints[:, 1] - joints[:, 2]
    forward = np.cross(left, up)
    forward /= np.linalg.norm(forward, axis=-1, keepdims=True)
    # humanoid3d faces +X at identity; left x up must point the same way (no mirroring)
    np.testing.assert_allclose(forward, np.tile([1.0, 0.0, 0.0], (20, 1)), atol=1e-6)
    toes = np.einsum("ti,ti->t", joints[:, 10] - joints[:, 7], forward)
    assert np.all(toes > 0.1)
    assert np.all(joints[:, 15, 1] > joints[:, 12, 1]) and np.all(joints[:, 12, 1] > joints[:, 0, 1])
    assert np.all(joints[:, 0, 1] > joints[:, 4, 1]) and np.all(joints[:, 4, 1] > joints[:, 7, 1])


def test_npy_and_own_bvh_dispatch(tmp_path: Path) -> None:
    rng = np.random.default_rng(3)
    joints = rng.normal(scale=0.3, size=(30, 22, 3)).astype(np.float32)
    joints[..., 1] -= joints[..., 1].min()
    np.save(tmp_path / "clip.npy", joints)
    np.testing.assert_array_equal(load_joints(tmp_path / "clip.npy"), joints)
    assert load_joints(tmp_path / "clip.npy", fps=60).shape == (10, 22, 3)
    # BVH written by us maps back by joint name: a turning, rising rest pose comes back exact
    rest = np.zeros((22, 3))
    for j in range(1, 22):
        rest[j] = rest[PARENTS[j]] + CANONICAL_OFFSETS[j]
    angle = np.linspace(0.0, 3.0, 30)
    c, s = np.cos(angle)[:, None], np.sin(angle)[:, None]
    moving = np.stack([c * rest[:, 0] + s * rest[:, 2], rest[:, 1] + 0.01 * np.arange(30)[:, None],
                       -s * rest[:, 0] + c * rest[:, 2]], axis=-1)
    moving[..., 1] -= moving[..., 1].min()
    back = load_joints(write_bvh(tmp_path / "clip.bvh", moving))
    assert np.abs(back - moving).max() < 1e-5
    canonical = to_canonical_lengths(joints)
    bones = np.linalg.norm(canonical[:, 1:] - canonical[:, list(PARENTS[1:])], axis=-1)
    np.testing.assert_allclose(bones, np.tile(BONE_LENGTHS[1:], (30, 1)), atol=1e-5)


def test_dispatch_errors(tmp_path: Path) -> None:
    (tmp_path / "clip.fbx").write_text("x")
    with pytest.raises(MotionFormatError, match=r"clip\.fbx: unsupported motion file type '\.fbx'"):
        load_joints(tmp_path / "clip.fbx")
    with pytest.raises(MotionFormatError, match="no such file"):
        load_joints(tmp_path / "missing.bvh")
    (tmp_path / "42_01.amc").write_text("1\nroot 0 0 0 0 0 0\n")
    with pytest.raises(MotionFormatError, match=r"42_01\.amc: no ASF skeleton found"):
        load_joints(tmp_path / "42_01.amc")
    np.save(tmp_path / "wide.npy", np.zeros((5, 10)))
    with pytest.raises(MotionFormatError, match=r"wide\.npy: expected \(T, 22, 3\)"):
        load_joints(tmp_path / "wide.npy")


def test_features_hook(shared_data: Path) -> None:
    if importlib.util.find_spec("simdiff.motion.features") is None:
        pytest.skip("simdiff.motion.features is not written yet")
    sample = shared_data / "humanml3d" / "samples"
    joints = load_joints(sample / "new_joint_vecs" / "012314.npy")
    reference = np.load(sample / "new_joints" / "012314.npy")
    assert joints.shape == reference.shape
    assert np.abs(joints - reference).max() < 1e-3


def _yaw_aligned_error(a: np.ndarray, b: np.ndarray) -> float:
    """Mean per-joint distance after the best rotation about Y plus translation."""
    n = min(len(a), len(b))
    x, y = a[:n].reshape(-1, 3).astype(np.float64), b[:n].reshape(-1, 3).astype(np.float64)
    xc, yc = x - x.mean(0), y - y.mean(0)
    h = xc[:, [0, 2]].T @ yc[:, [0, 2]]
    u, _, vt = np.linalg.svd(h)
    r2 = vt.T @ np.diag([1.0, np.sign(np.linalg.det(vt.T @ u.T))]) @ u.T
    rot = np.eye(3)
    rot[np.ix_([0, 2], [0, 2])] = r2
    return float(np.linalg.norm(xc @ rot.T - yc, axis=-1).mean())


def test_real_cmu_amc_and_bvh(shared_data: Path, tmp_path: Path) -> None:
    cmu = shared_data / "cmu"
    amc = load_joints(cmu / "amc" / "02_01.amc").astype(np.float64)
    assert amc.shape == (58, 22, 3)
    feet = amc[:, [7, 8, 10, 11], 1].min(axis=1)
    assert np.median(feet) < 0.06  # a foot is on the floor
    assert np.all(amc[:, 15, 1] > amc[:, 0, 1] + 0.4)  # up is +Y
    assert 1.4 < np.median(amc[:, 15, 1]) < 1.65  # head joint: ~1.6-1.7 m tall subject
    with tarfile.open(cmu / "bvh.tar.xz", "r:xz") as archive:
        for member in archive:
            if member.name == "bvh/02_01.bvh":
                archive.extract(member, tmp_path, filter="data")
                break
    bvh_path = tmp_path / "bvh" / "02_01.bvh"
    bvh = load_joints(bvh_path).astype(np.float64)
    assert bvh.shape == (58, 22, 3)
    assert np.median(bvh[:, [7, 8, 10, 11], 1].min(axis=1)) < 0.06
    # same capture on two rigs: on canonical bones they agree to ~3 cm (measured 3.0 cm)
    a = load_joints(cmu / "amc" / "02_01.amc", canonical=True)
    b = load_joints(bvh_path, canonical=True)
    assert _yaw_aligned_error(a, b) < 0.035
