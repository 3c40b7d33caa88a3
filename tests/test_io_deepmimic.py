"""DeepMimic humanoid3d reader: FK of hand-checked poses, errors, a real CMU clip."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from simdiff.errors import MotionFormatError
from simdiff.motion.io.deepmimic import VALUES_PER_FRAME, read_deepmimic

IDENTITY = [1.0, 0.0, 0.0, 0.0]


def _frame(root=(1.0, 0.9, 2.0), root_q=IDENTITY, r_knee=0.0, l_elbow=0.0) -> list[float]:
    """dt, root pos, root quat, chest, neck, r hip, r knee, r ankle, r shoulder, r elbow,
    l hip, l knee, l ankle, l shoulder, l elbow."""
    q = IDENTITY
    return [1 / 30, *root, *root_q, *q, *q, *q, r_knee, *q, *q, 0.0, *q, 0.0, *q, *q, l_elbow]


def _write(tmp_path: Path, frames: list[list[float]], name: str = "clip.txt") -> Path:
    path = tmp_path / name
    rows = ",\n".join(json.dumps([float(v) for v in f]) for f in frames)
    path.write_text('{\n"Loop": "none",\n"Frames":\n[\n' + rows + "\n]\n}\n")
    return path


def test_frame_layout() -> None:
    assert VALUES_PER_FRAME == 44
    assert len(_frame()) == 44


def test_rest_pose_positions(tmp_path: Path) -> None:
    rig = read_deepmimic(_write(tmp_path, [_frame(), _frame()]))
    assert rig.fps == pytest.approx(30.0)
    assert rig.positions.shape == (2, 19, 3)
    p = {n: rig.positions[0, i].astype(np.float64) for i, n in enumerate(rig.names)}
    np.testing.assert_allclose(p["chest"], [1.0, 1.136151, 2.0], atol=1e-6)
    np.testing.assert_allclose(p["neck"], [1.0, 1.360045, 2.0], atol=1e-6)
    np.testing.assert_allclose(p["right_hip"], [1.0, 0.9, 2.084887], atol=1e-6)
    np.testing.assert_allclose(p["right_ankle"], [1.0, 0.068584, 2.084887], atol=1e-6)
    np.testing.assert_allclose(p["left_wrist"], [0.97595, 0.845916, 1.81689], atol=1e-6)
    np.testing.assert_allclose(p["right_toe"], [1.12, 0.023584, 2.084887], atol=1e-6)
    np.testing.assert_allclose(p["head"], [1.0, 1.520045, 2.0], atol=1e-6)


def test_root_turn_and_revolute_knee(tmp_path: Path) -> None:
    # root turned 90 deg about +Y (x -> -z), right knee bent by -90 deg about its local Z
    s = np.sqrt(0.5)
    turned = _frame(root=(0.0, 1.0, 0.0), root_q=[s, 0.0, s, 0.0], r_knee=-np.pi / 2, l_elbow=np.pi / 2)
    rig = read_deepmimic(_write(tmp_path, [turned]))
    p = {n: rig.positions[0, i].astype(np.float64) for i, n in enumerate(rig.names)}
    np.testing.assert_allclose(p["right_hip"], [0.084887, 1.0, 0.0], atol=1e-6)
    np.testing.assert_allclose(p["right_knee"], [0.084887, 0.578454, 0.0], atol=1e-6)
    # the shin swings backwards: the character now faces -Z, so the ankle goes to +Z
    np.testing.assert_allclose(p["right_ankle"], [0.084887, 0.578454, 0.40987], atol=1e-6)
    # elbow +90 deg: the forearm points forward (-Z after the turn)
    forearm = p["left_wrist"] - p["left_elbow"]
    np.testing.assert_allclose(forearm, [0.0, 0.0, -0.258947], atol=1e-6)


_CASES = {
    "short": (lambda f: f[:-1], "has 43 values"),
    "text": (lambda f: f[:5] + ["x"] + f[6:], "not a list of finite numbers"),
    "zero_quat": (lambda f: f[:8] + [0.0, 0.0, 0.0, 0.0] + f[12:], "zero quaternion"),
}


@pytest.mark.parametrize("case", sorted(_CASES))
def test_bad_frame_names_its_line(tmp_path: Path, case: str) -> None:
    edit, words = _CASES[case]
    frames = [_frame(), _frame(), edit(_frame())]
    path = tmp_path / "bad.txt"
    rows = ",\n".join(json.dumps(f) for f in frames)
    path.write_text('{\n"Loop": "wrap",\n"Frames":\n[\n' + rows + "\n]\n}\n")
    with pytest.raises(MotionFormatError) as err:
        read_deepmimic(path)
    message = str(err.value)
    assert "bad.txt:7:" in message and "frame 2" in message and words in message


def test_invalid_json_and_missing_frames(tmp_path: Path) -> None:
    path = tmp_path / "cut.txt"
    path.write_text('{\n"Loop": "none",\n"Frames":\n[\n[0.1, 0.2,\n')
    with pytest.raises(MotionFormatError, match=r"cut\.txt:\d+: invalid JSON"):
        read_deepmimic(path)
    other = tmp_path / "other.json"
    other.write_text('{"Skeleton": {}}')
    with pytest.raises(MotionFormatError, match=r"other\.json:1: not a DeepMimic motion"):
        read_deepmimic(other)


def test_real_clip(shared_data: Path) -> None:
    rig = read_deepmimic(shared_data / "cmu" / "deepmimic" / "02_01.txt")
    assert rig.fps == pytest.approx(30.0)
    assert rig.positions.shape == (85, 19, 3)
    pos = rig.positions.astype(np.float64)
    # fixed link lengths of the humanoid3d: thigh 0.421546 m, shin 0.40987 m
    thigh = np.linalg.norm(pos[:, rig.index("left_knee")] - pos[:, rig.index("left_hip")], axis=-1)
    np.testing.assert_allclose(thigh, 0.421546, atol=1e-5)
    assert np.median(pos[:, rig.index("root"), 1]) == pytest.approx(0.86, abs=0.05)
    assert pos[:, rig.index("head"), 1].min() > 1.3
