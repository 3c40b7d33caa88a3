"""Hostile command lines: every size has a bound, nan/inf/out-of-range numbers are one line, non-finite results
and failed runs leave nothing behind, model configs must match their weights, SIGTERM cleans up."""

from __future__ import annotations

import argparse
import ast
import errno
import json
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import torch

from simdiff.cli.main import build_parser, main
from simdiff.errors import SimdiffError
from simdiff.inference.generator import MotionGenerator
from simdiff.model import ModelConfig, SimConfig, backbone_preset, build_network
from simdiff.motion import synthetic

PACKAGE = Path(__file__).resolve().parents[1] / "simdiff"


def one_line(capsys, needle: str) -> str:
    """The one error line (a progress note such as ``simdiff: rendering … …`` may precede it on a slow machine)."""
    err = capsys.readouterr().err.strip()
    lines = [line for line in err.splitlines() if not line.endswith(" …")]
    assert "Traceback" not in err and len(lines) == 1, err
    assert lines[0].startswith("simdiff: error:") and needle in lines[0], err
    return lines[0]


def save_tiny(folder: Path, std: float = 0.05) -> Path:
    torch.manual_seed(0)
    config = ModelConfig(backbone=backbone_preset("tiny"), sim=SimConfig())
    MotionGenerator(build_network(config), config, std=torch.full((263,), std)).save(folder)
    return folder


@pytest.fixture(scope="module")
def tiny_model(tmp_path_factory) -> Path:
    return save_tiny(tmp_path_factory.mktemp("tiny"))


@pytest.fixture(autouse=True)
def restore_threads():
    threads = torch.get_num_threads()
    yield
    torch.set_num_threads(threads)


@pytest.mark.parametrize("argv, needle", [
    (["sample", "--model", "m", "--text", "x", "--batch", "100000"], "argument --batch: 100000 is outside 1..1024"),
    (["train", "backbone", "--synthetic", "4", "--out", "r", "--batch-size", "1000000"],
     "argument --batch-size: 1000000 is outside 1..256"),
    (["render", "a.npy", "--out", "a.png", "--frames", "100000"], "argument --frames: 100000 is outside 1..64"),
    (["render", "a.npy", "--out", "a.png", "--size", "100000", "10"], "argument --size: 100000 is outside 16..4096"),
    (["generate", "x", "--num-samples", "100000"], "argument --num-samples: 100000 is outside 1..64"),
    (["serve", "--queue", "100000"], "argument --queue: 100000 is outside 1..64"),
    (["sample", "--model", "m", "--text", "x", "--env", "nan", "0", "0"], "argument --env: 'nan' is not a finite"),
    (["sample", "--model", "m", "--text", "x", "--env", "1e30", "0", "0"], "argument --env: 1e30 is outside"),
    (["generate", "x", "--wind", "1e30", "0", "--force"], "argument --wind: 1e30 is outside [-200, 200]"),
    (["generate", "x", "--gravity=-1e30", "--force"], "argument --gravity: -1e30 is outside [-100, -0.1]"),
    (["generate", "x", "--guidance", "1e30"], "argument --guidance: 1e30 is outside [0, 20]"),
    (["generate", "x", "--length", "0.1"], "argument --length: 0.1 is outside [0.5, 9.8]"),
    (["generate", "x", "--seed", str(2**70)], f"argument --seed: {2**70} is outside 0..4294967295"),
    (["convert", "a.bvh", "b.npy", "--fps", "0"], "argument --fps: 0 is outside [1, 1000]"),
    (["convert", "a.bvh", "b.npy", "--fps", "-5"], "argument --fps: -5 is outside [1, 1000]"),
    (["convert", "a.bvh", "b.npy", "--fps", "nan"], "argument --fps: 'nan' is not a finite number"),
    (["audit", "a.npy", "--fps", "0"], "argument --fps: 0 is outside [1, 1000]"),
    (["train", "backbone", "--synthetic", "4", "--out", "r", "--lr", "nan"], "argument --lr: 'nan' is not a finite"),
    (["evaluate", "train-evaluator", "--corpus", "c", "--out", "o", "--epochs", "inf"], "argument --epochs: 'inf'"),
])
def test_hostile_numbers_are_one_line_before_any_work(tmp_path: Path, monkeypatch, capsys, argv, needle) -> None:
    monkeypatch.chdir(tmp_path)
    assert main(argv) == 2
    one_line(capsys, needle)
    assert not any(tmp_path.iterdir())  # refused before anything was created


def _actions(parser: argparse.ArgumentParser, prog: str = "simdiff"):
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield from _actions(sub, f"{prog} {name}")
        elif action.option_strings or action.dest != "help":
            yield prog, action


def test_every_numeric_option_is_checked_and_refuses_nan_and_inf() -> None:
    unchecked, accepting = [], []
    for prog, action in _actions(build_parser()):
        name = "/".join(action.option_strings) or action.dest
        if action.type in (int, float):
            unchecked.append(f"{prog} {name}")
        elif getattr(action.type, "__name__", "") in ("integer", "real"):
            for bad in ("nan", "inf", "-inf", "1e400"):
                try:
                    action.type(bad)
                except argparse.ArgumentTypeError:
                    continue
                accepting.append(f"{prog} {name} {bad}")
    assert not unchecked, f"plain int/float options (use simdiff.cli.options.integer/real): {unchecked}"
    assert not accepting, accepting


def test_a_non_finite_sample_is_refused_and_nothing_is_written(tmp_path: Path, capsys) -> None:
    model = save_tiny(tmp_path / "m", std=3e38)  # finite weights whose un-normalised features overflow to inf
    out = tmp_path / "out"
    assert main(["generate", "a person walks", "--length", "0.5", "--steps", "1", "--model", str(model),
                 "--out", str(out), "-q"]) == 2
    one_line(capsys, "sampling gave non-finite values")
    assert not out.exists()
    assert main(["sample", "--model", str(model), "--text", "x", "--length", "10", "--steps", "1",
                 "--out", str(tmp_path / "s"), "--no-progress"]) == 2
    one_line(capsys, "non-finite")
    assert not any((tmp_path / "s").iterdir()) if (tmp_path / "s").exists() else True


def test_a_full_disk_while_writing_leaves_no_partial_set(tiny_model: Path, tmp_path: Path, monkeypatch,
                                                         capsys) -> None:
    from simdiff.motion.io import bvh_writer

    def full(path, *args, **kwargs):
        Path(path).with_suffix(".tmp").write_bytes(b"half")  # a writer that got part-way
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(path))

    monkeypatch.setattr(bvh_writer, "write_bvh", full)
    out = tmp_path / "new"
    assert main(["generate", "a person walks", "--length", "0.5", "--steps", "1", "--model", str(tiny_model),
                 "--format", "npy,bvh", "--out", str(out), "-q"]) != 0
    assert "no space left on device" in capsys.readouterr().err
    assert not out.exists()  # the folder this run created is gone with its staged files
    kept = tmp_path / "kept"
    kept.mkdir()
    (kept / "mine.txt").write_text("a user's file")
    assert main(["generate", "a person walks", "--length", "0.5", "--steps", "1", "--model", str(tiny_model),
                 "--format", "npy,bvh", "--out", str(kept), "-q"]) != 0
    assert sorted(p.name for p in kept.iterdir()) == ["mine.txt"]


def test_generate_below_the_shortest_length_and_foot_lock_on_two_frames() -> None:
    from simdiff.motion.foot_lock import clean_feet
    from simdiff.product.request import frames_from

    with pytest.raises(SimdiffError, match="10..196 frames"):
        frames_from(0.1)
    assert frames_from(0.5) == 10
    two = clean_feet(torch.randn(1, 2, 263) * 0.1, torch.tensor([2]))  # used to raise on an aliasing write
    assert two.shape == (1, 2, 263) and bool(torch.isfinite(two).all())


def test_sample_chunks_many_motions_into_one_complete_set(tiny_model: Path, tmp_path: Path, monkeypatch) -> None:
    from simdiff.cli.commands import sample

    monkeypatch.setattr(sample, "CHUNK", 2)
    out = tmp_path / "s"
    assert main(["sample", "--model", str(tiny_model), "--text", "a", "--text", "b", "--batch", "3", "--length",
                 "10", "--steps", "1", "--out", str(out), "--no-progress"]) == 0
    index = json.loads((out / "samples.json").read_text())
    assert [s["text"] for s in index["samples"]] == ["a", "a", "a", "b", "b", "b"]
    files = sorted(p.name for p in out.iterdir())
    assert len(files) == 13 and not [f for f in files if f.startswith(".")]
    first = [np.load(out / f"sample_{i:03d}.npy") for i in range(6)]
    assert not np.allclose(first[0], first[2])  # chunks draw different noise


def test_a_video_the_encoder_truncated_is_refused_and_removed(tmp_path: Path, monkeypatch, capsys) -> None:
    import imageio_ffmpeg

    real = imageio_ffmpeg.write_frames

    def truncating(*args, **kwargs):  # an encoder on a full disk: takes every frame, keeps the first few
        gen = real(*args, **kwargs)

        def wrapped():
            n = 0
            frame = yield
            while True:
                if frame is not None and n < 3:
                    gen.send(frame)
                n += frame is not None
                try:
                    frame = yield
                except GeneratorExit:
                    gen.close()
                    return
        w = wrapped()
        gen.send(None)
        return w

    monkeypatch.setattr(imageio_ffmpeg, "write_frames", truncating)
    motion = tmp_path / "walk.npy"
    np.save(motion, synthetic.walk(30).astype(np.float32))
    assert main(["render", str(motion), "--out", str(tmp_path / "walk.mp4")]) == 2
    one_line(capsys, "holds 3 of 30 frames")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["walk.npy"]


@pytest.mark.parametrize("key, needle", [
    ("num_layers", "weight(s) the config describes are absent"),
    ("latent_dim", "in the file"),
])
def test_a_config_that_does_not_match_the_weights_is_one_line(tmp_path: Path, capsys, key, needle) -> None:
    model = save_tiny(tmp_path / "m")
    config = json.loads((model / "config.json").read_text())
    config["backbone"][key] *= 2
    (model / "config.json").write_text(json.dumps(config))
    assert main(["generate", "x", "--length", "0.5", "--steps", "1", "--model", str(model),
                 "--out", str(tmp_path / "o"), "-q"]) == 2
    assert "config.json does not match model.safetensors" in one_line(capsys, needle)
    assert not (tmp_path / "o").exists()


def test_the_output_does_not_follow_the_load(tiny_model: Path, tmp_path: Path, monkeypatch) -> None:
    argv = ["generate", "a person walks", "--length", "0.5", "--steps", "2", "--model", str(tiny_model),
            "--format", "npy", "-q"]
    threads = torch.get_num_threads()
    assert main([*argv, "--out", str(tmp_path / "a")]) == 0
    monkeypatch.setattr(os, "getloadavg", lambda: (64.0, 64.0, 64.0))
    assert main([*argv, "--out", str(tmp_path / "b")]) == 0
    a, b = (np.load(tmp_path / d / "sample0_joints.npy") for d in "ab")
    assert a.tobytes() == b.tobytes()
    assert json.loads((tmp_path / "b" / "generation.json").read_text())["threads"] == threads


def _python_hints(node: ast.AST) -> list[str]:
    texts = [n.value for n in ast.walk(node) if isinstance(n, ast.Constant) and isinstance(n.value, str)]
    return [t for t in texts if re.search(r"\b[a-z_]+=(True|False|None)\b|\bpass [a-z_]+=|keyword argument|allow_pickle", t)]


def test_error_messages_speak_cli_not_python() -> None:
    found = []
    for path in PACKAGE.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Raise) and node.exc is not None:
                found += [f"{path.relative_to(PACKAGE)}:{node.lineno}: {t!r}" for t in _python_hints(node.exc)]
    assert not found, found


def test_sigterm_during_generate_leaves_nothing_and_one_line(tmp_path: Path) -> None:
    out = tmp_path / "out"
    proc = subprocess.Popen([sys.executable, "-m", "simdiff", "generate", "a person walks", "--sampler", "ddpm",
                             "--steps", "1000", "--out", str(out), "-q"], cwd=tmp_path, stderr=subprocess.PIPE,
                            text=True)
    deadline = time.monotonic() + 120
    while not out.exists() and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.1)
    time.sleep(1.0)  # the model loads and sampling starts
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 143, err
    assert err.strip() == "simdiff: terminated"
    assert not out.exists()


def test_render_refuses_sizes_beyond_its_bounds_before_drawing(tmp_path: Path, capsys) -> None:
    long = tmp_path / "long.npy"
    np.save(long, np.zeros((12001, 22, 3), np.float32))
    assert main(["render", str(long), "--out", str(tmp_path / "x.mp4")]) == 2
    one_line(capsys, "has 12001 frames; render at most 12000")
    mid = tmp_path / "mid.npy"
    np.save(mid, np.zeros((2001, 22, 3), np.float32))
    assert main(["render", str(mid), str(mid), "--out", str(tmp_path / "x.gif")]) == 2
    one_line(capsys, "write an .mp4 instead")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["long.npy", "mid.npy"]


def test_a_gif_stops_at_its_memory_budget(tmp_path: Path, monkeypatch) -> None:
    from simdiff.viz import video

    monkeypatch.setattr(video, "MAX_GIF_BYTES", 10 * 64 * 64 * 3)
    frames = (np.zeros((64, 64, 3), np.uint8) for _ in range(1000))
    with pytest.raises(SimdiffError, match="write an .mp4 instead"):
        video.write_gif(frames, tmp_path / "x.gif", 20)
    assert not any(tmp_path.iterdir())


def test_a_device_or_other_non_regular_target_is_refused(tmp_path: Path, capsys) -> None:
    from simdiff import fsio

    fifo = tmp_path / "pipe.npy"
    os.mkfifo(fifo)
    with pytest.raises(SimdiffError, match="is not a regular file"):
        fsio.save_npy(fifo, np.zeros((2, 22, 3), np.float32))
    assert fifo.exists() and not fifo.is_file()  # not replaced by a rename
    motion = tmp_path / "walk.npy"
    np.save(motion, synthetic.walk(12).astype(np.float32))
    assert main(["convert", str(motion), "/dev/full"]) == 2
    one_line(capsys, "")
    assert Path("/dev/full").is_char_device()


def test_a_gif_refuses_rates_it_cannot_play(tmp_path: Path, capsys) -> None:
    motion = tmp_path / "walk.npy"
    np.save(motion, synthetic.walk(12).astype(np.float32))
    assert main(["render", str(motion), "--out", str(tmp_path / "w.gif"), "--fps", "1000"]) == 2
    one_line(capsys, "a GIF plays at 0.01..50 fps, got 1000; write an .mp4 instead")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["walk.npy"]


@pytest.mark.parametrize("value", ["-1e308", "-inf", "-1E3", "-.5e1"])
def test_negative_numbers_in_exponent_form_are_values(tmp_path: Path, capsys, value) -> None:
    assert main(["generate", "x", "--gravity", value, "--length", "12"]) == 2
    assert "expected one argument" not in one_line(capsys, "argument --")


def test_a_failed_set_names_the_final_file_not_its_staged_copy(tmp_path: Path) -> None:
    from simdiff import fsio

    with pytest.raises(SimdiffError) as info, fsio.output_set(tmp_path / "out") as stage:
        raise fsio.write_error(stage / "sample0.bvh", OSError(errno.ENOSPC, "full"))
    assert ".simdiff-partial" not in str(info.value) and str(tmp_path / "out" / "sample0.bvh") in str(info.value)


def test_a_second_run_into_the_same_folder_leaves_one_run(tiny_model: Path, tmp_path: Path) -> None:
    argv = ["generate", "a person walks", "--length", "0.5", "--steps", "1", "--model", str(tiny_model),
            "--format", "npy", "--out", str(tmp_path / "o"), "-q"]
    assert main([*argv, "--num-samples", "3"]) == 0
    (tmp_path / "o" / "notes.txt").write_text("a user's file")
    assert main(argv) == 0
    names = sorted(p.name for p in (tmp_path / "o").iterdir())
    assert names == ["generation.json", "notes.txt", "sample0_features.npy", "sample0_joints.npy"]


def test_an_unknown_option_points_at_the_subcommands_help(capsys) -> None:
    assert main(["generate", "x", "--nope"]) == 2
    one_line(capsys, "unrecognized arguments: --nope (see simdiff generate --help)")
    assert main(["data", "report", "c", "--nope"]) == 2
    one_line(capsys, "(see simdiff data report --help)")
