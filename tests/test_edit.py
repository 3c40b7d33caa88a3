"""``simdiff edit``: a motion re-played under φ (windows, the model's difference, the user's frame, the CLI)."""

from __future__ import annotations

import itertools
import json
from pathlib import Path

import numpy as np
import pytest

from simdiff.cli.main import main
from simdiff.diffusion.config import SamplingConfig
from simdiff.errors import SimdiffError
from simdiff.inference.editing import edit_motion
from simdiff.inference.replay import OVERLAP, blend_weights, replay_features, windows
from simdiff.motion import synthetic
from simdiff.motion.features import process_joints
from simdiff.motion.rigid import bone_lengths
from simdiff.train.testing import tiny_generator

CONFIG = SamplingConfig(steps=4, eta=0.0, edit_t=600, guidance=2.0, alpha=1.0, foot_lock=1.0)


pytestmark = pytest.mark.usefixtures("one_torch_thread")


@pytest.fixture(scope="module")
def gen():
    return tiny_generator()


def turned(joints: np.ndarray, angle: float, shift: tuple[float, float], scale: float = 1.0) -> np.ndarray:
    """``joints`` turned about Y by ``angle`` (rad), scaled about the origin and moved by ``shift`` (x, z) m."""
    c, s = np.cos(angle), np.sin(angle)
    rot = np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])
    return joints @ rot.T * scale + np.array([shift[0], 0.0, shift[1]])


@pytest.mark.parametrize("frames", [10, 196, 197, 300, 353, 800, 1000])
def test_windows_cover_the_motion_and_weights_sum_to_one(frames: int) -> None:
    spans = windows(frames)
    assert spans[0][0] == 0 and spans[-1][1] == frames
    assert all(0 < e - s <= 196 for s, e in spans)
    assert all(b[0] < a[1] and a[1] - b[0] >= OVERLAP for a, b in itertools.pairwise(spans))  # neighbours overlap
    w = blend_weights(frames, spans)
    assert np.allclose(w.sum(0), 1.0) and (w >= 0).all()
    for i, (s, e) in enumerate(spans):
        assert not w[i, :s].any() and not w[i, e:].any()
    if len(spans) > 1:
        assert np.all(np.abs(np.diff(w, axis=1)) <= 2.0 / OVERLAP)  # ramps, no step


def test_earth_without_wind_gives_the_motion_back(gen) -> None:
    joints = turned(synthetic.jump(60), 0.8, (2.0, -1.0))
    features = process_joints(joints).features
    replay = replay_features(gen, features, CONFIG, (-9.81, 0.0, 0.0))
    assert np.array_equal(replay.features, features) and not replay.difference.any()
    edited = edit_motion(gen, joints, CONFIG, (-9.81, 0.0, 0.0))
    assert edited.joints.shape == joints.shape and float(np.abs(edited.joints - joints).max()) < 1e-3


def test_another_gravity_changes_the_motion_deterministically(gen) -> None:
    features = process_joints(synthetic.jump(60)).features
    a = replay_features(gen, features, CONFIG, (-1.6, 0.0, 0.0), seed=3)
    b = replay_features(gen, features, CONFIG, (-1.6, 0.0, 0.0), seed=3)
    c = replay_features(gen, features, CONFIG, (-1.6, 0.0, 0.0), seed=4)
    assert a.difference.any() and np.array_equal(a.features, b.features) and not np.array_equal(a.features, c.features)
    assert np.allclose(a.features, features + a.difference)
    wind = replay_features(gen, features, CONFIG, (-9.81, 5.0, 0.0), seed=3)
    assert wind.difference.any()


def test_a_long_motion_runs_in_windows(gen) -> None:
    features = process_joints(synthetic.walk(300)).features
    replay = replay_features(gen, features, CONFIG.updated(steps=2), (-3.7, 0.0, 0.0))
    assert replay.features.shape == features.shape and np.isfinite(replay.features).all()
    assert np.abs(replay.difference[150:200]).sum() > 0  # the second window's part


def test_the_edit_is_the_same_in_any_frame_and_keeps_the_skeleton(gen) -> None:
    """Turning and moving the input turns and moves the edit the same way; a larger body keeps its bones."""
    joints = synthetic.jump(60)
    plain = edit_motion(gen, joints, CONFIG, (-1.6, 0.0, 0.0), seed=1)
    moved = edit_motion(gen, turned(joints, 1.1, (3.0, -2.0)), CONFIG, (-1.6, 0.0, 0.0), seed=1)
    assert plain.changed_m > 0.001
    assert float(np.abs(turned(plain.joints, 1.1, (3.0, -2.0)) - moved.joints).max()) < 1e-4
    big = turned(joints, 0.0, (0.0, 0.0), scale=1.2)
    lengths, source = bone_lengths(edit_motion(gen, big, CONFIG, (-1.6, 0.0, 0.0), seed=1).joints), bone_lengths(big)
    assert float(lengths.std(0).max()) < 1e-3 and np.allclose(lengths.mean(0), source.mean(0), atol=1e-3)


def test_bad_input_is_refused(gen) -> None:
    joints = synthetic.jump(60)
    with pytest.raises(SimdiffError, match="shape"):
        edit_motion(gen, joints[:, :20], CONFIG, (-1.6, 0.0, 0.0))
    with pytest.raises(SimdiffError, match="5 frames"):
        edit_motion(gen, joints[:5], CONFIG, (-1.6, 0.0, 0.0))
    nan = joints.copy()
    nan[3, 4, 1] = np.nan
    with pytest.raises(SimdiffError, match="NaN"):
        edit_motion(gen, nan, CONFIG, (-1.6, 0.0, 0.0))
    with pytest.raises(SimdiffError, match="continuous Sim Encoder"):
        replay_features(tiny_generator(sim=False), process_joints(joints).features, CONFIG, (-1.6, 0.0, 0.0))


@pytest.fixture(scope="module")
def tiny_model(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("tiny_edit")
    tiny_generator().save(folder)
    (folder / "sampling.json").write_text(json.dumps(CONFIG.to_dict()))
    return folder


def test_edit_cli_writes_the_edit_and_its_record(tiny_model: Path, tmp_path: Path, capsys) -> None:
    src = tmp_path / "jump.npy"
    np.save(src, synthetic.jump(40).astype(np.float32))
    out = tmp_path / "out"
    assert main(["edit", str(src), "--gravity", "-1.6", "--wind", "2", "0", "--model", str(tiny_model), "--out",
                 str(out), "--format", "npy,bvh,gif", "-q"]) == 0, capsys.readouterr().err
    names = sorted(p.name for p in out.iterdir())
    assert names == ["compare.gif", "edit.json", "edited.bvh", "edited_features.npy", "edited_joints.npy"]
    assert capsys.readouterr().out.split() == [str(out / n) for n in
                                               ["edited_joints.npy", "edited_features.npy", "edited.bvh",
                                                "compare.gif", "edit.json"]]
    meta = json.loads((out / "edit.json").read_text())
    assert meta["environment"] == {"gravity": -1.6, "wind": [2.0, 0.0]} and meta["frames"] == 40
    assert np.load(out / "edited_joints.npy").shape == (40, 22, 3)
    assert np.load(out / "edited_features.npy").shape == (40, 263)


@pytest.mark.parametrize("argv, needle", [
    (["--gravity", "3"], "--gravity"),
    (["--gravity", "-50"], "outside"),
    (["--wind", "0", "inf"], "--wind"),
    (["--format", "png"], "'png'"),
])
def test_edit_cli_bad_options_get_one_line(argv: list[str], needle: str, tiny_model: Path, tmp_path: Path,
                                           capsys) -> None:
    src = tmp_path / "jump.npy"
    np.save(src, synthetic.jump(40).astype(np.float32))
    assert main(["edit", str(src), *argv, "--model", str(tiny_model), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and needle in err and "Traceback" not in err
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("content, needle", [
    (np.zeros((40, 21, 3)), "22"),
    (np.zeros((1, 22, 3)), "frame"),
    (np.full((40, 22, 3), np.nan), "non-finite"),
    (np.zeros((40, 22, 3)), "not a body in metres"),
])
def test_edit_cli_bad_files_get_one_line(content: np.ndarray, needle: str, tiny_model: Path, tmp_path: Path,
                                         capsys) -> None:
    src = tmp_path / "bad.npy"
    np.save(src, content.astype(np.float32))
    assert main(["edit", str(src), "--gravity", "-1.6", "--model", str(tiny_model), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and needle in err and "Traceback" not in err, err
    assert not (tmp_path / "o").exists()
    assert main(["edit", str(tmp_path / "missing.bvh"), "--model", str(tiny_model)]) == 2
    assert "missing.bvh" in capsys.readouterr().err


@pytest.mark.parametrize("half", ["lower", "upper"])
def test_keep_half_keeps_it_and_makes_the_other_anew(gen, half: str) -> None:
    from simdiff.inference.editing import keep_half
    from simdiff.motion.skeleton import LOWER_BODY, UPPER_BODY

    walk = turned(synthetic.walk(40), 0.6, (1.0, 2.0))
    out = keep_half(gen, walk, CONFIG, (-9.81, 0.0, 0.0), half, "a person waves", seed=2)
    kept = LOWER_BODY if half == "lower" else UPPER_BODY
    other = [j for j in range(22) if j not in kept]
    assert out.joints.shape == walk.shape
    # the random tiny model's new half sits oddly on the kept one, so the rigid fit's compromise at the pelvis shows
    assert float(np.linalg.norm(out.joints[:, kept] - walk[:, kept], axis=-1).max()) < 0.05
    assert float(np.linalg.norm(out.joints[:, other] - walk[:, other], axis=-1).mean()) > 0.01
    assert float(bone_lengths(out.joints).std(0).max()) < 1e-3
    assert np.allclose(bone_lengths(out.joints).mean(0), bone_lengths(walk).mean(0), atol=2e-3)


def test_keep_half_of_a_long_motion_continues_across_windows(gen) -> None:
    from simdiff.inference.editing import keep_half
    from simdiff.motion.skeleton import LOWER_BODY

    walk = synthetic.walk(300)  # two windows of 196 frames sharing 92
    out = keep_half(gen, walk, CONFIG, (-9.81, 0.0, 0.0), "lower", "a person waves", seed=2)
    assert out.joints.shape == walk.shape and out.features.shape == (300, 263)
    kept = list(LOWER_BODY)
    assert float(np.linalg.norm(out.joints[:, kept] - walk[:, kept], axis=-1).max()) < 0.05
    assert float(bone_lengths(out.joints).std(0).max()) < 1e-3
    step = np.linalg.norm(np.diff(out.joints, axis=0), axis=-1).max(axis=1)  # fastest joint per frame, m/frame
    # the first window ends at frame 196: no faster there than a typical frame of this jittery random model (without
    # the overlap's keyframes and cross-fade it is the fastest step of the motion, 0.27 m against a median 0.17)
    assert step[195] <= np.median(step)


def test_keep_refuses_what_it_cannot_do(gen, tiny_model: Path, tmp_path: Path, capsys) -> None:
    from simdiff.inference.editing import keep_half

    with pytest.raises(SimdiffError, match="--keep must be"):
        keep_half(gen, synthetic.walk(40), CONFIG, None, "left", "a person waves")
    src = tmp_path / "walk.npy"
    np.save(src, synthetic.walk(40).astype(np.float32))
    assert main(["edit", str(src), "--keep", "lower", "--model", str(tiny_model), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "text prompt is empty" in err
    assert main(["edit", str(src), "--keep", "lower", "--text", "a person waves", "--model", str(tiny_model),
                 "--format", "npy", "--out", str(tmp_path / "k"), "-q"]) == 0, capsys.readouterr().err
    meta = json.loads((tmp_path / "k" / "edit.json").read_text())
    assert meta["keep"] == "lower" and meta["text"] == "a person waves"


def test_edit_reads_a_bvh_and_gives_it_back_at_earth(tiny_model: Path, tmp_path: Path, capsys) -> None:
    from simdiff.motion.io import load_joints
    from simdiff.motion.io.bvh_writer import write_bvh

    src = tmp_path / "walk.bvh"
    write_bvh(src, turned(synthetic.walk(60), 0.4, (1.0, -2.0)).astype(np.float32))
    assert main(["edit", str(src), "--model", str(tiny_model), "--format", "npy,bvh", "--out", str(tmp_path / "o"),
                 "-q"]) == 0, capsys.readouterr().err
    read = load_joints(src)
    edited = np.load(tmp_path / "o" / "edited_joints.npy")
    assert edited.shape == read.shape and float(np.abs(edited - read).max()) < 0.01
    assert np.abs(load_joints(tmp_path / "o" / "edited.bvh") - edited).max() < 0.01
