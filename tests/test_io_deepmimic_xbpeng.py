"""DeepMimic clips of the xbpeng set: variable frame durations, the ground clean-up applied
by ``retarget_rig`` for this rig, and real clips (acrobatics included)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from mocap_fixtures import extra_member

from simdiff.motion.io import load_joints, load_rig, retarget_rig
from simdiff.motion.io.ground import lift_penetrations

IDENTITY = [1.0, 0.0, 0.0, 0.0]


def _frame(dt: float, x: float, y: float = 0.9) -> list[float]:
    q = IDENTITY
    return [dt, x, y, 0.0, *q, *q, *q, *q, 0.0, *q, *q, 0.0, *q, 0.0, *q, *q, 0.0]


def _write(path: Path, frames: list[list[float]]) -> Path:
    rows = ",\n".join(json.dumps(f) for f in frames)
    path.write_text('{"Loop": "wrap", "Frames": [\n' + rows + "\n]}\n")
    return path


def test_variable_durations_are_retimed(tmp_path: Path) -> None:
    # 60 fps frames with one dropped frame (a 2/60 s step), root moving 1 m/s in x
    times = [k / 60 for k in range(10)] + [k / 60 for k in range(11, 30)]
    dts = list(np.diff(times)) + [0.0]
    path = _write(tmp_path / "roll.txt", [_frame(dt, t) for dt, t in zip(dts, times)])
    rig = load_rig(path)
    assert rig.fps == pytest.approx(60.0) and rig.meta["retimed"] is True
    assert rig.num_frames == 30  # the missing frame is interpolated back
    np.testing.assert_allclose(rig.joint("root")[:, 0], np.arange(30) / 60, atol=1e-6)
    steady = _write(tmp_path / "walk.txt", [_frame(1 / 30, k / 30) for k in range(5)])
    assert load_rig(steady).meta["retimed"] is False


def test_ground_cleanup_applied_by_retarget(tmp_path: Path) -> None:
    frames = [_frame(1 / 30, 0.0, 0.9) for _ in range(60)]
    for k in (20, 21):  # two frames dipping 4 cm through the floor
        frames[k][2] = 0.86
    rig = load_rig(_write(tmp_path / "clip.txt", frames))
    raw = retarget_rig(rig, clean=False)
    cleaned = retarget_rig(rig)
    np.testing.assert_allclose(cleaned, lift_penetrations(raw), atol=1e-6)
    assert np.median(raw[..., 1].min(axis=-1)) > 0.03  # raw floor set by the dip
    assert np.median(cleaned[..., 1].min(axis=-1)) < 0.01  # cleaned: feet back on it
    np.testing.assert_allclose(load_joints(tmp_path / "clip.txt"), cleaned, atol=1e-6)


@pytest.mark.parametrize("clip", ["humanoid3d_backflip.txt", "humanoid3d_roll.txt"])
def test_real_xbpeng_clip(shared_data: Path, tmp_path: Path, clip: str) -> None:
    path = extra_member(shared_data, "deepmimic-xbpeng.tar.xz", tmp_path, lambda n: n.endswith("/" + clip))
    rig = load_rig(path)
    joints = load_joints(path)
    assert joints.shape[1:] == (22, 3) and np.isfinite(joints).all()
    duration = rig.num_frames / rig.fps
    assert joints.shape[0] == pytest.approx(duration * 20, abs=2)
    assert joints[..., 1].min() == pytest.approx(0.0, abs=1e-6)
    # a flip or roll turns the body over: the head goes below the pelvis at some point
    assert np.any(joints[:, 15, 1] < joints[:, 0, 1])
