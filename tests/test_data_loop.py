"""Looped locomotion clips (simdiff/data/loop.py, ``simdiff data loop``) on synthetic walks."""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import numpy as np
import pytest

from simdiff.cli.main import main
from simdiff.data.clip_files import process_clip, write_clip
from simdiff.data.loop import find_period, loop_corpus, loop_joints
from simdiff.errors import SimdiffError
from simdiff.motion.kinematics import facing_direction
from simdiff.motion.skeleton import FACE_JOINTS
from simdiff.motion.synthetic import walk


def root_speed(joints: np.ndarray, fps: float = 20.0) -> float:
    """Mean horizontal (X–Z) pelvis speed (m/s) of (T, 22, 3) joints."""
    return float(np.linalg.norm(np.diff(np.asarray(joints)[:, 0, [0, 2]], axis=0), axis=1).mean() * fps)


def _max_step(joints: np.ndarray) -> float:
    return float(np.linalg.norm(np.diff(joints, axis=0), axis=-1).max())


def _yaw(joints: np.ndarray) -> np.ndarray:
    f = facing_direction(joints, FACE_JOINTS)
    return np.unwrap(np.arctan2(f[:, 0], f[:, 2]))


def test_a_cyclic_walk_loops_at_its_speed_without_a_seam() -> None:
    clip = walk(60, speed=1.3, stride_hz=1.0)  # one gait cycle = 20 frames
    period = find_period(clip)
    assert period.frames in (20, 40) and period.error < 1e-4
    looped = loop_joints(clip, 200, period.frames, start=period.start)
    assert looped.shape == (200, 22, 3) and looped.dtype == np.float32
    assert root_speed(looped) == pytest.approx(1.3, rel=0.01)
    assert _max_step(looped) <= _max_step(clip) * 1.01
    np.testing.assert_allclose(looped[: period.frames], clip[period.start : period.start + period.frames], atol=1e-5)


def test_a_turning_walk_keeps_turning_at_its_rate() -> None:
    clip = walk(60, speed=1.2, turn_rate=0.5)
    period = find_period(clip)
    looped = loop_joints(clip, 160, period.frames, start=period.start)
    assert np.diff(_yaw(looped)).mean() * 20 == pytest.approx(0.5, rel=0.03)
    assert root_speed(looped) == pytest.approx(root_speed(clip), rel=0.02)
    assert _max_step(looped) <= _max_step(clip) * 1.05


def test_a_run_that_starts_from_standing_is_looped_from_its_moving_frames() -> None:
    moving = walk(60, speed=2.0, stride_hz=1.25)
    standing = np.repeat(moving[:1], 8, axis=0)
    clip = np.concatenate([standing, moving])
    period = find_period(clip)
    assert period.start >= 4  # not the still frames, which repeat at any lag
    looped = loop_joints(clip, 120, period.frames, start=period.start)
    assert root_speed(looped) == pytest.approx(2.0, rel=0.05)


@pytest.mark.parametrize("clip, message", [
    (walk(12), "too short"),
    (walk(60, speed=0.0, amplitude=0.0, bounce=0.0), "nothing to loop"),
    (np.zeros((60, 21, 3)), "expected (frames, 22, 3)"),
])
def test_find_period_bad_input_is_one_line(clip: np.ndarray, message: str) -> None:
    with pytest.raises(SimdiffError, match=message.replace("(", r"\(").replace(")", r"\)")) as info:
        find_period(clip)
    assert "\n" not in str(info.value)
    with pytest.raises(SimdiffError, match="cannot loop"):
        loop_joints(walk(30), 100, period=28)


def _corpus(root: Path) -> Path:
    """A corpus: short runs (one padded), a short walk, a long run, a short run in val."""
    rows = [("run_a", "train", "run", 0, walk(50, speed=2.5, stride_hz=1.4), ["a person runs forward."]),
            ("Mrun_a", "train", "run", 0, walk(50, speed=2.5, stride_hz=1.4, phase=np.pi), ["a person runs forward."]),
            ("run_pad", "train", "run", 12, walk(50, speed=2.4), ["a person runs."]),
            ("walk_a", "train", "walk", 0, walk(50, speed=1.2), ["a person walks."]),
            ("run_long", "train", "run", 0, walk(130, speed=1.5), ["a person runs slowly."]),
            ("run_val", "val", "run", 0, walk(50, speed=2.5), ["a person runs."])]
    clips = []
    for cid, split, kind, padded, joints, captions in rows:
        features, recovered = process_clip(cid, joints)
        write_clip(root, cid, features, recovered, [f"{c}#a/DET#0.0#0.0" for c in captions])
        clips.append({"id": cid, "split": split, "motion_type": kind, "padded_frames": padded,
                      "frames": int(features.shape[0]), "captions": captions,
                      "mirror_of": "run_a" if cid.startswith("M") else None})
    (root / "manifest.json").write_text(json.dumps({"clips": clips}))
    for split in ("train", "val"):
        (root / f"{split}.txt").write_text("".join(f"{c['id']}\n" for c in clips if c["split"] == split))
    np.save(root / "Mean.npy", np.zeros(263, np.float32))
    return root


def _digest(root: Path) -> dict[str, str]:
    return {str(p.relative_to(root)): hashlib.sha256(p.read_bytes()).hexdigest() for p in sorted(root.rglob("*"))
            if p.is_file()}


def test_loop_corpus_adds_train_loops_and_leaves_the_corpus_as_it_was(tmp_path: Path, capsys) -> None:
    root = _corpus(tmp_path / "c")
    before = _digest(root)
    assert main(["data", "loop", str(root), "--frames", "100", "--quiet"]) == 0
    assert "2 loops of 100 frames" in capsys.readouterr().out
    after = _digest(root)
    assert {k: v for k, v in after.items() if k in before} == before  # nothing of the corpus changed
    record = json.loads((root / "loops.json").read_text())
    assert [r["loop_of"] for r in record["looped"]] == ["run_a", "Mrun_a"]  # not padded, long, walk or val clips
    assert record["skipped"] == [{"id": "run_pad", "why": "12 held frames"}]
    ids = (root / "train_loop.txt").read_text().split()
    assert ids == (root / "train.txt").read_text().split() + ["Lrun_a", "LMrun_a"]
    vecs = np.load(root / "new_joint_vecs" / "Lrun_a.npy")
    assert vecs.shape == (100, 263) and np.isfinite(vecs).all()
    assert root_speed(np.load(root / "new_joints" / "Lrun_a.npy")) == pytest.approx(2.5, rel=0.03)
    assert (root / "texts" / "Lrun_a.txt").read_text() == (root / "texts" / "run_a.txt").read_text()
    assert main(["data", "loop", str(root), "--frames", "100", "--quiet"]) == 0
    assert _digest(root) == after  # a rerun writes the same bytes


@pytest.mark.parametrize("args, message", [
    (["--types", "swim"], "--types swim: not a motion_type"),
    (["--frames", "1"], "argument --frames: 1 is outside"),
    (["--out-split", "train"], "--out-split 'train': choose a new split name"),
    (["--split", "nope"], "nope.txt: missing"),
])
def test_loop_cli_bad_input_is_one_line(tmp_path: Path, capsys, args: list[str], message: str) -> None:
    root = _corpus(tmp_path / "c")
    assert main(["data", "loop", str(root), "--quiet", *args]) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1
    with pytest.raises(SimdiffError, match="manifest.json: missing"):
        loop_corpus(tmp_path / "nowhere", ["run"], 100)
