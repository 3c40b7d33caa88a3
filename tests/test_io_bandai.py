"""Bandai-Namco BVH rig: names, centimetres, 30 fps, placement (synthetic file + one real)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from mocap_fixtures import POS_ROT, ROT, bvh_text, channel_count, extra_member

from simdiff.errors import MotionFormatError
from simdiff.motion.io import load_joints, load_rig
from simdiff.motion.io.retarget import joint_map_for
from simdiff.motion.io.rigs import BANDAI_MAP
from simdiff.motion.skeleton import JOINT_NAMES

J = JOINT_NAMES.index

# Rest pose as the real rig: each chain along its joints' local +X (spine up, arms and legs
# along their length); the Hips rotation Zrot = 90 deg stands it up (local +X -> world +Y),
# local +Z (the character's left) stays world +Z, so the body faces world -X.
JOINTS = [
    ("joint_Root", None, (0.0, 0.0, 0.0), POS_ROT),
    ("Hips", "joint_Root", (0.0, 93.9, -3.0), POS_ROT),
    ("Spine", "Hips", (15.7, 0.0, 0.0), ROT),
    ("Chest", "Spine", (9.0, 0.0, 0.0), ROT),
    ("Neck", "Chest", (16.4, 0.0, 0.0), ROT),
    ("Head", "Neck", (6.5, 0.0, 0.0), ROT),
    ("Shoulder_L", "Chest", (13.0, 0.0, 5.0), ROT),
    ("UpperArm_L", "Shoulder_L", (0.0, 0.0, 12.0), ROT),
    ("LowerArm_L", "UpperArm_L", (-27.0, 0.0, 0.0), ROT),
    ("Hand_L", "LowerArm_L", (-24.0, 0.0, 0.0), ROT),
    ("Shoulder_R", "Chest", (13.0, 0.0, -5.0), ROT),
    ("UpperArm_R", "Shoulder_R", (0.0, 0.0, -12.0), ROT),
    ("LowerArm_R", "UpperArm_R", (-27.0, 0.0, 0.0), ROT),
    ("Hand_R", "LowerArm_R", (-24.0, 0.0, 0.0), ROT),
    ("UpperLeg_L", "Hips", (-2.0, 0.0, 9.0), ROT),
    ("LowerLeg_L", "UpperLeg_L", (-42.0, 0.0, 0.0), ROT),
    ("Foot_L", "LowerLeg_L", (-42.0, 0.0, 0.0), ROT),
    ("Toes_L", "Foot_L", (-8.0, 12.0, 0.0), ROT),
    ("UpperLeg_R", "Hips", (-2.0, 0.0, -9.0), ROT),
    ("LowerLeg_R", "UpperLeg_R", (-42.0, 0.0, 0.0), ROT),
    ("Foot_R", "LowerLeg_R", (-42.0, 0.0, 0.0), ROT),
    ("Toes_R", "Foot_R", (-8.0, 12.0, 0.0), ROT),
]
ENDS = {"Head": (0.0, 0.0, 0.0), "Hand_L": (0.0, 0.0, 0.0), "Hand_R": (0.0, 0.0, 0.0),
        "Toes_L": (0.0, 0.0, 0.0), "Toes_R": (0.0, 0.0, 0.0)}


def _write(tmp_path: Path, frames: int = 6) -> Path:
    values = np.zeros((frames, channel_count(JOINTS)))
    values[:, 6:9] = [0.0, 93.9, -3.0]  # Hips position channels (cm)
    values[:, 9] = 90.0  # Hips Zrotation: stand the rest pose up
    values[:, 6] -= np.arange(frames) * 4.0  # walk towards -X (forward) at 1.2 m/s
    path = tmp_path / "dataset-1_walk_normal_001.bvh"
    path.write_text(bvh_text(JOINTS, values, 1 / 30, ENDS))
    return path


def test_bandai_names_units_rate(tmp_path: Path) -> None:
    path = _write(tmp_path)
    rig = load_rig(path)
    assert rig.meta["rig"].name == "bandai"
    assert rig.meta["scale"] == 0.01  # the rig's known unit: centimetres
    assert rig.fps == pytest.approx(30.0)
    assert joint_map_for(rig) is BANDAI_MAP
    joints = load_joints(path)
    assert joints.dtype == np.float32 and joints.shape == (4, 22, 3)  # 6 frames at 30 -> 4 at 20 fps
    # metres: 0.84 m leg, head 1.3-1.8 m above the floor, feet (toes) on the floor
    leg = np.linalg.norm(joints[0, J("left_hip")] - joints[0, J("left_ankle")])
    assert leg == pytest.approx(0.84, abs=1e-3)
    assert 1.3 < joints[0, J("head"), 1] < 1.8
    assert joints[..., 1].min() == pytest.approx(0.0, abs=1e-6)
    assert joints[0, J("left_foot"), 1] == pytest.approx(0.0, abs=1e-3)
    # walking towards -X at 4 cm per source frame = 1.2 m/s
    speed = np.diff(joints[:, 0, 0]).mean() * 20
    assert speed == pytest.approx(-1.2, abs=1e-3)


def test_bandai_placement(tmp_path: Path) -> None:
    j = load_joints(_write(tmp_path))[0].astype(np.float64)
    hips = 0.5 * (j[J("left_hip")] + j[J("right_hip")])
    trunk = j[J("neck")] - hips
    # pelvis 15 % of the way from the hip centre to the neck, spine joints in order above it
    np.testing.assert_allclose(j[J("pelvis")], hips + 0.15 * trunk, atol=1e-5)
    heights = [j[J(n), 1] for n in ("pelvis", "spine1", "spine2", "spine3", "neck", "head")]
    assert np.all(np.diff(heights) > 0)
    assert (j[J("spine2"), 1] - hips[1]) / trunk[1] == pytest.approx(0.565, abs=0.03)
    # the head joint sits in front of the neck (the body faces -X): rest axes are right
    assert j[J("neck"), 0] - j[J("head"), 0] == pytest.approx(0.037, abs=2e-3)
    # left is +Z
    assert j[J("left_hip"), 2] > j[J("right_hip"), 2]


def test_bandai_units_override(tmp_path: Path) -> None:
    path = _write(tmp_path)
    metres = load_joints(path)
    as_m = load_joints(path, units="m")
    np.testing.assert_allclose(as_m, metres * 100.0, rtol=1e-4, atol=1e-3)
    np.testing.assert_allclose(load_joints(path, units=0.01), metres, atol=1e-6)
    with pytest.raises(MotionFormatError, match="unknown units 'furlong'"):
        load_joints(path, units="furlong")
    with pytest.raises(MotionFormatError, match="BVH files only"):
        npy = tmp_path / "joints.npy"
        np.save(npy, metres)
        load_joints(npy, units="cm")


def test_real_bandai_file(shared_data: Path, tmp_path: Path) -> None:
    path = extra_member(shared_data, "bandai-namco.tar.xz", tmp_path, lambda n: n.endswith(".bvh"))
    rig = load_rig(path)
    assert rig.meta["rig"].name == "bandai" and rig.fps == pytest.approx(30.0, abs=1e-3)
    joints = load_joints(path)
    assert joints.shape[1:] == (22, 3) and np.isfinite(joints).all()
    leg = np.linalg.norm(joints[:, J("left_hip")] - joints[:, J("left_knee")], axis=-1).mean()
    assert 0.3 < leg < 0.5  # a thigh in metres (about 0.39 m): the centimetres were converted
    assert 1.1 < np.percentile(joints[:, J("head"), 1], 90) < 1.8
    assert joints[..., 1].min() == pytest.approx(0.0, abs=1e-6)
