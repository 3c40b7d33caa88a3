"""Daz-style CMU BVH (43 joints, centimetres; also the acLSTM dance folders): names, units,
the start-up T-pose and blend, the folder readme frame rate, placement (synthetic + real)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from mocap_fixtures import POS_ROT, ROT, bvh_text, channel_count, extra_member

from simdiff.motion.io import load_joints, load_rig
from simdiff.motion.io.bvh import leading_transient
from simdiff.motion.io.rates import folder_fps_hint
from simdiff.motion.skeleton import JOINT_NAMES

J = JOINT_NAMES.index

# cm, Y up, faces +Z, left +X (as the real files); fingers and eyes left out (not needed)
JOINTS = [
    ("hip", None, (0.0, 0.0, 0.0), POS_ROT),
    ("abdomen", "hip", (0.0, 20.7, -0.7), ROT),
    ("chest", "abdomen", (0.0, 11.7, -0.5), ROT),
    ("neck", "chest", (0.0, 22.2, -2.2), ROT),
    ("head", "neck", (-0.2, 7.1, 1.2), ROT),
    ("rCollar", "chest", (-2.7, 19.3, -4.9), ROT),
    ("rShldr", "rCollar", (-8.8, -2.0, 1.5), ROT),
    ("rForeArm", "rShldr", (0.0, -28.2, 0.5), ROT),
    ("rHand", "rForeArm", (0.0, -22.6, 0.0), ROT),
    ("lCollar", "chest", (2.7, 19.3, -4.9), ROT),
    ("lShldr", "lCollar", (8.8, -2.0, 1.5), ROT),
    ("lForeArm", "lShldr", (0.0, -28.2, 0.5), ROT),
    ("lHand", "lForeArm", (0.0, -22.6, 0.0), ROT),
    ("rButtock", "hip", (-8.8, 4.4, 1.2), ROT),
    ("rThigh", "rButtock", (0.0, -1.7, -2.2), ROT),
    ("rShin", "rThigh", (0.0, -36.8, 0.7), ROT),
    ("rFoot", "rShin", (0.7, -45.1, -5.1), ROT),
    ("lButtock", "hip", (8.8, 4.4, 1.2), ROT),
    ("lThigh", "lButtock", (0.0, -1.7, -2.2), ROT),
    ("lShin", "lThigh", (0.0, -36.8, 0.7), ROT),
    ("lFoot", "lShin", (-0.7, -45.1, -5.1), ROT),
]
ENDS = {"head": (0.0, 10.0, 0.0), "rHand": (0.0, -8.0, 0.0), "lHand": (0.0, -8.0, 0.0),
        "rFoot": (-1.1, -3.7, 12.1), "lFoot": (1.1, -3.7, 12.1)}
HIP_HEIGHT = 1.7 - 4.4 + 36.8 + 45.1 + 3.7  # the toe end sites touch y = 0


def _write(path: Path, count: int = 40, blend: int = 4) -> Path:
    """A walk forward (+Z) at 1.2 m/s, 120 fps, starting with a T-pose at the origin and
    ``blend`` frames interpolated from it."""
    values = np.zeros((count, channel_count(JOINTS)))
    values[:, 1] = HIP_HEIGHT
    values[:, 2] = np.arange(count) * 1.0  # 1 cm per frame at 120 fps
    start = values[blend + 1].copy()
    tpose = np.zeros_like(start)
    tpose[6:] = 25.0
    for k in range(blend + 1):
        values[k] = tpose + (start - tpose) * k / (blend + 1)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(bvh_text(JOINTS, values, 1 / 120, ENDS))
    return path


def test_daz_names_units_transient(tmp_path: Path) -> None:
    path = _write(tmp_path / "daz" / "12_01.bvh")
    rig = load_rig(path)
    assert rig.meta["rig"].name == "daz" and rig.meta["scale"] == 0.01
    assert rig.fps == pytest.approx(120.0) and rig.meta["fps_source"] == "header"
    assert rig.meta["dropped_frames"] == 5  # the T-pose and the 4 blend frames
    assert rig.num_frames == 35
    np.testing.assert_allclose(rig.joint("hip")[:, 2], (np.arange(35) + 5) * 0.01, atol=1e-6)
    joints = load_joints(path)
    assert joints.shape[1:] == (22, 3) and joints.dtype == np.float32
    leg = np.linalg.norm(joints[:, J("left_hip")] - joints[:, J("left_ankle")], axis=-1)
    assert leg.mean() == pytest.approx(np.linalg.norm([0.7, 81.9, 4.4]) / 100, abs=2e-3)
    np.testing.assert_allclose(joints[:, J("left_foot"), 1], 0.0, atol=1e-4)


def test_daz_placement(tmp_path: Path) -> None:
    j = load_joints(_write(tmp_path / "12_01.bvh"))[0].astype(np.float64)
    hips = 0.5 * (j[J("left_hip")] + j[J("right_hip")])
    np.testing.assert_allclose(j[J("pelvis")], hips + 0.15 * (j[J("neck")] - hips), atol=1e-5)
    heights = [j[J(n), 1] for n in ("pelvis", "spine1", "spine2", "spine3", "neck", "head")]
    assert np.all(np.diff(heights) > 0)
    # head 2.8 cm in front of the head joint (faces +Z); collars between neck and shoulders
    assert j[J("head"), 2] - j[J("neck"), 2] > 0.03
    assert 0.0 < j[J("left_collar"), 0] < j[J("left_shoulder"), 0]
    assert j[J("left_collar"), 1] < j[J("neck"), 1]


def test_readme_frame_rate(tmp_path: Path) -> None:
    path = _write(tmp_path / "aclstm" / "salsa" / "01.bvh")
    (tmp_path / "aclstm" / "readme.txt").write_text("indian framerate 120\nsalsa  framerate 60\n")
    assert folder_fps_hint(path) == 60.0
    rig = load_rig(path)
    assert rig.fps == 60.0 and rig.meta["fps_source"] == "readme"
    assert load_rig(path, fps=120.0).fps == 120.0  # an explicit rate wins
    assert folder_fps_hint(tmp_path / "aclstm" / "martial" / "01.bvh") is None


def test_leading_transient_keeps_clean_starts() -> None:
    rng = np.random.default_rng(0)
    walk = np.cumsum(rng.normal(0, 0.002, size=(100, 10, 3)), axis=0) + rng.normal(size=(1, 10, 3))
    assert leading_transient(walk, 120.0) == 0
    jumped = walk.copy()
    jumped[:3] += 0.5  # three frames away from the body, as a T-pose left at the origin
    assert leading_transient(jumped, 120.0) == 3
    late = walk.copy()
    late[50:] += 0.5  # a jump after the first 0.1 s is motion, not a start-up transient
    assert leading_transient(late, 120.0) == 0
    rising = walk.copy()
    rising[:6, :, 1] += np.linspace(0.12, 0.0, 6)[:, None]  # real motion at 0.7 m/s, 30 fps
    assert leading_transient(rising, 30.0) == 0


def test_real_daz_file(shared_data: Path, tmp_path: Path) -> None:
    path = extra_member(shared_data, "cmu-bvh.tar.xz", tmp_path,
                        lambda n: "/daz/12_" in n and n.endswith(".bvh"))
    rig = load_rig(path)
    assert rig.meta["rig"].name == "daz" and rig.meta["dropped_frames"] >= 1
    joints = load_joints(path)
    leg = np.linalg.norm(joints[:, J("left_hip")] - joints[:, J("left_ankle")], axis=-1).mean()
    assert 0.7 < leg < 1.0  # centimetres converted
    lowest = joints[..., 1].min(axis=-1)
    assert np.median(lowest) < 0.05  # on the floor, not lifted by a start-up T-pose
