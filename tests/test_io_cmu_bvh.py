"""CMU BVH conversions: Motionbuilder-style (31 joints, CMU ASF units, first frame a T-pose,
thorax dropped) and the ASF-named variant (synthetic files + one real file)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from mocap_fixtures import POS_ROT, ROT, bvh_text, channel_count, extra_member

from simdiff.motion.io import load_joints, load_rig
from simdiff.motion.io.rigs.cmu import ASFBVH_FROM_MB
from simdiff.motion.skeleton import JOINT_NAMES

J = JOINT_NAMES.index
UNIT = 0.0254 / 0.45  # metres per CMU ASF length unit

# straight standing rest pose, Y up, facing +Z, left +X; lengths in CMU ASF units
BACK, NECK = 2.0, 1.7
MB_JOINTS = [
    ("Hips", None, (0.0, 0.0, 0.0), POS_ROT),
    ("LHipJoint", "Hips", (0.0, 0.0, 0.0), ROT),
    ("LeftUpLeg", "LHipJoint", (1.6, -1.8, 0.0), ROT),
    ("LeftLeg", "LeftUpLeg", (0.0, -7.4, 0.0), ROT),
    ("LeftFoot", "LeftLeg", (0.0, -7.4, 0.0), ROT),
    ("LeftToeBase", "LeftFoot", (0.0, -1.0, 2.0), ROT),
    ("RHipJoint", "Hips", (0.0, 0.0, 0.0), ROT),
    ("RightUpLeg", "RHipJoint", (-1.6, -1.8, 0.0), ROT),
    ("RightLeg", "RightUpLeg", (0.0, -7.4, 0.0), ROT),
    ("RightFoot", "RightLeg", (0.0, -7.4, 0.0), ROT),
    ("RightToeBase", "RightFoot", (0.0, -1.0, 2.0), ROT),
    ("LowerBack", "Hips", (0.0, 0.0, 0.0), ROT),
    ("Spine", "LowerBack", (0.0, BACK, 0.0), ROT),
    ("Spine1", "Spine", (0.0, BACK, 0.0), ROT),
    ("Neck", "Spine1", (0.0, 0.0, 0.0), ROT),  # the dropped thorax: zero offset
    ("Neck1", "Neck", (0.0, NECK, 0.0), ROT),
    ("Head", "Neck1", (0.0, NECK, 0.0), ROT),
    ("LeftShoulder", "Spine1", (0.0, 0.0, 0.0), ROT),
    ("LeftArm", "LeftShoulder", (3.4, 0.5, 0.0), ROT),
    ("LeftForeArm", "LeftArm", (0.0, -5.5, 0.0), ROT),
    ("LeftHand", "LeftForeArm", (0.0, -4.5, 0.0), ROT),
    ("RightShoulder", "Spine1", (0.0, 0.0, 0.0), ROT),
    ("RightArm", "RightShoulder", (-3.4, 0.5, 0.0), ROT),
    ("RightForeArm", "RightArm", (0.0, -5.5, 0.0), ROT),
    ("RightHand", "RightForeArm", (0.0, -4.5, 0.0), ROT),
]
ENDS = {"Head": (0.0, 1.8, 0.0), "LeftToeBase": (0.0, 0.0, 1.0), "RightToeBase": (0.0, 0.0, 1.0),
        "LeftHand": (0.0, -1.0, 0.0), "RightHand": (0.0, -1.0, 0.0)}
HIP_HEIGHT = 1.8 + 14.8 + 1.0  # units: the toes touch y = 0


def _frames(count: int, tpose: bool) -> np.ndarray:
    values = np.zeros((count, channel_count(MB_JOINTS)))
    values[:, 1] = HIP_HEIGHT
    values[:, 2] = np.arange(count) * 0.2  # 0.2 units per frame forward
    if tpose:  # frame 0: a T-pose somewhere else (arms up, at the origin)
        values[0, :3] = [0.0, 0.0, 0.0]
        values[0, 6:] = 30.0
    return values


def _write(tmp_path: Path, name: str, joints=MB_JOINTS, ends=ENDS, tpose: bool = True,
           count: int = 25) -> Path:
    path = tmp_path / name
    path.write_text(bvh_text(joints, _frames(count, tpose), 1 / 120, ends))
    return path


def test_motionbuilder_units_tpose_rate(tmp_path: Path) -> None:
    path = _write(tmp_path, "08_01.bvh")
    rig = load_rig(path)
    assert rig.meta["rig"].name == "cmu_mb"
    assert rig.meta["scale"] == pytest.approx(UNIT)
    assert rig.fps == pytest.approx(120.0)
    assert rig.num_frames == 24 and rig.meta["dropped_frames"] == 1  # the T-pose
    np.testing.assert_allclose(rig.joint("Hips")[0], [0.0, HIP_HEIGHT * UNIT, 0.2 * UNIT], atol=1e-5)
    joints = load_joints(path)
    assert joints.shape == (4, 22, 3)  # 24 frames at 120 fps -> 4 at 20 fps
    leg = np.linalg.norm(joints[:, J("left_hip")] - joints[:, J("left_ankle")], axis=-1)
    np.testing.assert_allclose(leg, 14.8 * UNIT, atol=1e-4)
    assert joints[..., 1].min() == pytest.approx(0.0, abs=1e-6)
    np.testing.assert_allclose(joints[:, J("left_foot"), 1], 0.0, atol=1e-4)


def test_motionbuilder_thorax_restored(tmp_path: Path) -> None:
    j = load_joints(_write(tmp_path, "08_01.bvh"))[0].astype(np.float64)
    hips = 0.5 * (j[J("left_hip")] + j[J("right_hip")])
    # neck = lowerneck end: 1.8 (hip joints below the root) + lowerback + upperback +
    # the restored thorax (= upperback) + lowerneck
    assert j[J("neck"), 1] - hips[1] == pytest.approx((1.8 + 3 * BACK + NECK) * UNIT, abs=1e-4)
    # without the clean-up the neck is one thorax lower
    raw = load_joints(_write(tmp_path, "08_01.bvh"), clean=False)[0]
    assert j[J("neck"), 1] - raw[J("neck"), 1] == pytest.approx(BACK * UNIT, abs=1e-4)
    # placement as the AMC map: pelvis 15 % up the trunk, head in front of the neck axis
    np.testing.assert_allclose(j[J("pelvis")], hips + 0.15 * (j[J("neck")] - hips), atol=1e-5)
    assert j[J("head"), 2] > j[J("neck"), 2] + 0.03
    assert j[J("left_shoulder"), 0] > 0.15 and j[J("right_shoulder"), 0] < -0.15


def test_asf_named_cmu_bvh(tmp_path: Path) -> None:
    rename = dict(ASFBVH_FROM_MB, Hips="hip", LHipJoint="lhipjoint", RHipJoint="rhipjoint",
                  LowerBack="lowerback")
    joints = [(rename[n], rename.get(p) if p else None, o, c) for n, p, o, c in MB_JOINTS]
    ends = {rename[k]: v for k, v in ENDS.items()}
    asf_named = load_joints(_write(tmp_path, "16_01.bvh", joints, ends))
    mb = load_joints(_write(tmp_path, "08_01.bvh"))
    assert load_rig(tmp_path / "16_01.bvh").meta["rig"].name == "cmu_asf_bvh"
    np.testing.assert_allclose(asf_named, mb, atol=1e-5)


def test_real_motionbuilder_file(shared_data: Path, tmp_path: Path) -> None:
    path = extra_member(shared_data, "cmu-bvh.tar.xz", tmp_path,
                        lambda n: "/motionbuilder/" in n and n.endswith(".bvh"))
    rig = load_rig(path)
    assert rig.meta["rig"].name == "cmu_mb" and rig.meta["dropped_frames"] >= 1
    joints = load_joints(path)
    assert joints.shape[1:] == (22, 3) and np.isfinite(joints).all()
    leg = np.linalg.norm(joints[:, J("left_hip")] - joints[:, J("left_ankle")], axis=-1).mean()
    assert 0.7 < leg < 1.0  # metres: the CMU unit (inch / 0.45) was applied
    assert 1.3 < np.percentile(joints[:, J("head"), 1], 90) < 1.8
