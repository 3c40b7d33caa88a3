"""``generate --keyframes``: the checks on the file, the guide, the final pass and the command."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import torch

from simdiff.cli.main import main
from simdiff.errors import SimdiffError
from simdiff.inference.keyframes import (
    KeyframeFrame,
    KeyframeGuide,
    check_keyframes,
    keyframe_frame,
    meet_keyframes,
)
from simdiff.motion import synthetic
from simdiff.motion.features import process_joints
from simdiff.motion.rigid import bone_lengths
from simdiff.train.testing import tiny_generator

pytestmark = pytest.mark.usefixtures("one_torch_thread")


def free(frames: int = 60) -> np.ndarray:
    return np.full((frames, 22, 3), np.nan)


def speed(joints: np.ndarray) -> float:
    """Fastest joint, m/s at 20 fps."""
    return float(np.linalg.norm(np.diff(joints, axis=0), axis=-1).max() * 20)


@pytest.mark.parametrize("make, needle", [
    (lambda: np.zeros((60, 21, 3)), "shape"),
    (lambda: free(5), "5 frames"),
    (lambda: free(197), "197 frames"),
    (lambda: free(), "all NaN"),
    (lambda: np.where(np.arange(60)[:, None, None] == 3, np.inf, free()), "infinite value at frame 3"),
    (lambda: np.array(["a"] * 60 * 66).reshape(60, 22, 3), "dtype"),
])
def test_malformed_keyframes_are_named(make, needle: str) -> None:
    with pytest.raises(SimdiffError, match=needle):
        check_keyframes(make())


def test_partial_joints_unreachable_and_two_bodies_are_refused() -> None:
    walk = synthetic.walk(60)
    keys = free()
    keys[10, 5, :2] = walk[10, 5, :2]
    with pytest.raises(SimdiffError, match="joint 5 at frame 10 is partly NaN"):
        check_keyframes(keys)
    keys = free()
    keys[0, 0, [0, 2]] = 0.0
    keys[2, 0, [0, 2]] = [5.0, 0.0]  # 5 m in 0.1 s
    with pytest.raises(SimdiffError, match="joint 0 moves 50 m/s between frames 0 and 2"):
        check_keyframes(keys)
    keys = free()
    keys[0], keys[59] = walk[0], walk[59] * 1.3  # a larger body at the end
    with pytest.raises(SimdiffError, match="one skeleton"):
        check_keyframes(keys)
    keys = free()
    keys[0] = walk[0] * 0.01  # centimetres, not metres
    with pytest.raises(SimdiffError, match="not a body in metres"):
        check_keyframes(keys)
    keys = free()
    keys[::10, 0, [0, 2]] = walk[::10, 0, [0, 2]]  # a root path: x/z alone is allowed
    assert np.isfinite(check_keyframes(keys)).sum() == 12


def test_the_keyframes_frame_round_trips_and_keeps_free_entries_free() -> None:
    walk = synthetic.walk(40)
    c, s = np.cos(0.9), np.sin(0.9)
    turned = walk @ np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]]).T + np.array([2.0, 0.0, -1.0])
    frame = keyframe_frame(turned)
    assert frame.offset == pytest.approx((turned[0, 0, 0], turned[0, 0, 2]))
    assert np.allclose(frame.to_keyframes(frame.to_generated(turned)), turned)
    facing = keyframe_frame(frame.to_generated(turned))
    assert facing.yaw == pytest.approx(keyframe_frame(walk).yaw, abs=1e-6)
    path = free(40)
    path[:, 0, [0, 2]] = turned[:, 0, [0, 2]]
    moved = KeyframeFrame(0.5, (1.0, 2.0)).to_generated(path)
    assert np.isfinite(moved[:, 0, [0, 2]]).all() and np.isnan(moved[:, 0, 1]).all()


def test_meet_keyframes_meets_every_entry_smoothly_on_one_skeleton() -> None:
    walk = synthetic.walk(80)
    rng = np.random.default_rng(0)
    keys = free(80)
    keys[0], keys[79], keys[40] = walk[0], walk[79], walk[40]
    keys[60, 0, [0, 2]] = walk[60, 0, [0, 2]]
    drifted = walk + np.linspace(0, 1, 80)[:, None, None] * np.array([0.3, 0.0, -0.2])  # 36 cm off at the end
    drifted[:, 1:] += 0.02 * rng.standard_normal((1, 21, 3))
    met = meet_keyframes(drifted, keys)
    given = np.isfinite(keys)
    assert float(np.abs(np.where(given, met - np.nan_to_num(keys), 0.0)).max()) < 1e-3
    assert float(bone_lengths(met).std(0).max()) < 1e-4
    assert speed(met) < speed(walk) + 1.0  # no spike at the keyframes


def test_the_guide_pulls_x0_onto_the_keyframes() -> None:
    gen = tiny_generator()
    walk = synthetic.walk(41)
    keys = free(40)
    keys[0], keys[39] = walk[0], walk[39]
    guide = KeyframeGuide(keyframe_frame(keys).to_generated(keys), gen.mean, gen.std)
    torch.manual_seed(0)
    feats = torch.as_tensor(process_joints(synthetic.walk(41, speed=0.5)).features)[None]
    x0 = (feats - gen.mean) / gen.std
    before = float(guide.error(x0))
    after = float(guide.error(guide.polish(x0)))
    assert after < 0.05 * before


@pytest.fixture(scope="module")
def tiny_model(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("tiny_keys")
    tiny_generator().save(folder)
    return folder


def test_generate_meets_the_keyframes(tiny_model: Path, tmp_path: Path, capsys) -> None:
    walk = synthetic.walk(30)
    keys = free(30)
    keys[0], keys[29] = walk[0], walk[29]
    keys[15, 0, [0, 2]] = walk[15, 0, [0, 2]] + 0.1
    np.save(tmp_path / "keys.npy", keys)
    assert main(["generate", "a person walks", "--keyframes", str(tmp_path / "keys.npy"), "--steps", "3",
                 "--model", str(tiny_model), "--format", "npy", "--out", str(tmp_path / "o"), "-q"]) == 0, \
        capsys.readouterr().err
    joints = np.load(tmp_path / "o" / "sample0_joints.npy")
    assert joints.shape == (30, 22, 3)
    given = np.isfinite(keys)
    assert float(np.linalg.norm(np.where(given, joints - np.nan_to_num(keys), 0.0), axis=-1).max()) < 0.02
    record = json.loads((tmp_path / "o" / "generation.json").read_text())["keyframes"]
    assert record["entries"] == 45 and record["max_error_m"][0] < 0.02


@pytest.mark.parametrize("content, extra, needle", [
    (np.zeros((30, 22, 2)), [], "shape"),
    (np.full((30, 22, 3), np.nan), [], "all NaN"),
    (None, ["--length", "2"], "leave --length out"),
])
def test_generate_bad_keyframes_get_one_line(content, extra: list[str], needle: str, tiny_model: Path,
                                             tmp_path: Path, capsys) -> None:
    if content is None:
        content = free(30)
        content[0] = synthetic.walk(30)[0]
    np.save(tmp_path / "k.npy", content)
    assert main(["generate", "a person walks", "--keyframes", str(tmp_path / "k.npy"), *extra, "--model",
                 str(tiny_model), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and needle in err and "Traceback" not in err, err
    assert not (tmp_path / "o").exists()
    assert main(["generate", "a person walks", "--keyframes", str(tmp_path / "none.npy")]) == 2
    assert "none.npy" in capsys.readouterr().err


def test_a_root_path_with_poses_and_a_late_partial_joint() -> None:
    """Root x/z on every frame plus a whole pose (the root's y free) is fitted on the pose's skeleton; a partly-NaN
    joint after a legal root path entry is still refused; coordinates beyond a kilometre are refused."""
    w = synthetic.walk(40)
    keys = free(40)
    keys[:, 0, [0, 2]] = w[:, 0, [0, 2]]
    keys[20, 1:] = w[20, 1:]
    keys = check_keyframes(keys)
    met = meet_keyframes(w + 0.05, keys)
    given = np.isfinite(keys)
    assert np.isfinite(met).all()
    assert float(np.abs(np.where(given, met - np.nan_to_num(keys), 0.0)).max()) < 0.01
    bad = free(40)
    bad[0, 0, [0, 2]] = 0.0
    bad[5, 5, 0] = 0.3
    with pytest.raises(SimdiffError, match="joint 5 at frame 5 is partly NaN"):
        check_keyframes(bad)
    far = free(40)
    far[:, 0, [0, 2]] = 1e200
    with pytest.raises(SimdiffError, match="beyond 1000 m at frame 0"):
        check_keyframes(far)


def test_generate_warns_when_a_lone_joint_is_not_met(tiny_model: Path, tmp_path: Path, capsys) -> None:
    w = synthetic.walk(30)
    keys = free(30)
    keys[0] = w[0]
    keys[15, 20] = w[15, 20] + np.array([0.5, 0.4, 0.0])  # a wrist 64 cm off its arm's reach
    np.save(tmp_path / "k.npy", keys)
    assert main(["generate", "a person walks", "--keyframes", str(tmp_path / "k.npy"), "--steps", "2", "--model",
                 str(tiny_model), "--format", "npy", "--out", str(tmp_path / "o"), "-q"]) == 0
    record = json.loads((tmp_path / "o" / "generation.json").read_text())["keyframes"]
    err = capsys.readouterr().err
    assert (record["max_error_m"][0] > 0.02) == ("warning: a keyframe entry is" in err), err


def test_generate_warns_when_keyframe_poses_sink_the_feet(tiny_model: Path, tmp_path: Path, capsys) -> None:
    w = synthetic.walk(40)
    keys = free(40)
    keys[0], keys[-1] = 1.3 * w[0], 1.3 * w[-1]  # poses on a skeleton 1.3× the model's
    np.save(tmp_path / "k.npy", keys)
    assert main(["generate", "a person walks", "--keyframes", str(tmp_path / "k.npy"), "--steps", "2", "--model",
                 str(tiny_model), "--format", "npy", "--out", str(tmp_path / "o"), "-q"]) == 0
    lowest = json.loads((tmp_path / "o" / "generation.json").read_text())["samples"][0]["lowest_m"]
    err = capsys.readouterr().err
    assert lowest < -0.05 and "under the floor (keyframe poses on a skeleton larger" in err, err
