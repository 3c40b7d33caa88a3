"""Hostile data on the command line: tiny frame rates, implausible coordinates, broken corpus manifests, outputs
that would overwrite their inputs, several files of which some are bad, failed runs that must leave nothing."""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import pytest

from simdiff.cli.main import main
from simdiff.errors import MotionFormatError, SimdiffError
from simdiff.limits import MAX_COORD, MIN_FPS
from simdiff.motion import synthetic
from simdiff.motion.io import load_joints, read_bvh, write_bvh


def error_lines(capsys) -> tuple[str, list[str]]:
    """(stdout, the ``simdiff: error:`` lines of stderr); fails on a traceback or a Python exception name."""
    captured = capsys.readouterr()
    err = captured.err
    assert "Traceback" not in err and "LinAlgError" not in err + captured.out, err
    lines = [part for line in err.splitlines() for part in line.split("\r")]  # a progress bar may share a line
    return captured.out, [line for line in lines if line.startswith("simdiff: error:")]


def one_error(capsys, *parts: str) -> str:
    out, lines = error_lines(capsys)
    assert len(lines) == 1, lines
    for part in parts:
        assert part in lines[0], lines[0]
    return lines[0]


@pytest.fixture
def work(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.chdir(tmp_path)
    walk = synthetic.walk()
    np.save(tmp_path / "good.npy", walk.astype(np.float32))
    write_bvh(tmp_path / "good.bvh", walk[:10])
    return tmp_path


# 1. frame rates ------------------------------------------------------------------------------------------------

TINY_RATES = ["1e-320", "1e-300", "1e-10", "0.001", "0.5"]


@pytest.mark.parametrize("fps", TINY_RATES)
@pytest.mark.parametrize("argv", [["convert", "good.bvh", "o.npy"], ["track", "good.bvh"], ["audit", "good.bvh"],
                                  ["render", "good.npy", "--out", "o.png"]])
def test_tiny_frame_rates_are_refused_before_any_work(work: Path, capsys, argv: list[str], fps: str) -> None:
    assert main([*argv, "--fps", fps]) == 2
    one_error(capsys, f"argument --fps: {fps} is outside [1, 1000]")
    assert not (work / "o.npy").exists() and not (work / "o.png").exists()


@pytest.mark.parametrize("fps", [1e-320, 1e-300, 1e-10, 0.001, 0.5])
def test_library_refuses_rates_below_min_fps(work: Path, fps: float) -> None:
    with pytest.raises(SimdiffError, match=r"below 1 Hz"):
        load_joints(work / "good.bvh", fps=fps)
    with pytest.raises(SimdiffError, match=r"below 1 Hz"):
        load_joints(work / "good.npy", fps=fps)


def test_bvh_frame_time_longer_than_one_second_is_refused(work: Path) -> None:
    text = (work / "good.bvh").read_text().replace("Frame Time: 0.05000000", "Frame Time: 1000")
    (work / "slow.bvh").write_text(text)
    with pytest.raises(MotionFormatError, match=r"slow\.bvh:\d+: Frame Time .* got 1000"):
        read_bvh(work / "slow.bvh")
    assert MIN_FPS == 1.0


def test_convert_fps_help_matches_behaviour(work: Path, capsys) -> None:
    """``--fps`` overrides the BVH's own Frame Time, and the help says so."""
    with pytest.raises(SystemExit):
        main(["convert", "--help"])
    help_text = " ".join(capsys.readouterr().out.split())
    assert "overriding the file's own" in help_text and "when the file does not say" not in help_text
    assert main(["convert", "good.bvh", "own.npy"]) == 0
    assert main(["convert", "good.bvh", "half.npy", "--fps", "10"]) == 0
    own, half = np.load(work / "own.npy"), np.load(work / "half.npy")
    assert len(half) > 1.8 * len(own)  # 10 frames read at 10 Hz last twice as long as at the header's 20 Hz


# 2. implausible coordinates ------------------------------------------------------------------------------------

@pytest.mark.parametrize("shape", [(30, 22, 3), (30, 263)])
@pytest.mark.parametrize("argv", [["metrics"], ["render", "--out", "o.png"], ["audit", "--no-track"],
                                  ["convert", "--", "o.npy"]])
def test_huge_coordinates_are_one_line_naming_the_file(work: Path, capsys, shape, argv: list[str]) -> None:
    np.save(work / "huge.npy", np.full(shape, 1e30, dtype=np.float32))
    args = [*argv[:1], "huge.npy", *argv[1:]] if argv[0] != "convert" else ["convert", "huge.npy", "o.npy"]
    assert main(args) == 2
    one_error(capsys, "huge.npy", f"±{MAX_COORD:g} m")
    assert not (work / "o.png").exists() and not (work / "o.npy").exists()


def test_coordinate_bound_is_10_km(work: Path) -> None:
    joints = synthetic.walk().astype(np.float32)
    np.save(work / "far.npy", joints + np.float32(2 * MAX_COORD))
    np.save(work / "near.npy", joints + np.float32(0.5 * MAX_COORD))
    with pytest.raises(MotionFormatError, match=r"far\.npy: coordinates reach"):
        load_joints(work / "far.npy")
    assert load_joints(work / "near.npy").shape == joints.shape


# 3. manifests --------------------------------------------------------------------------------------------------

@pytest.mark.parametrize("text, needle", [("", "not valid JSON"), ("[]", "holds a list"), ("{", "not valid JSON"),
                                          ('{"clips": 5}', "clips is a number"), ("null", "holds null"),
                                          ('{"clips": [7]}', "clips[0] is a number"),
                                          ('{"clips": [{"id": "../x"}]}', "not a plain file name")])
@pytest.mark.parametrize("command", [["data", "loop"], ["data", "report"]])
def test_broken_manifest_is_one_line_naming_it(work: Path, capsys, text: str, needle: str, command) -> None:
    corpus = work / "corpus"
    corpus.mkdir()
    (corpus / "manifest.json").write_text(text)
    (corpus / "train.txt").write_text("a\n")
    assert main([*command, "corpus", "--no-crosscheck"] if command[1] == "report" else [*command, "corpus"]) == 2
    one_error(capsys, "corpus/manifest.json", needle)
    assert not (corpus / "report").exists()


def test_report_on_clips_without_licence_names_the_field(work: Path, capsys) -> None:
    clip = {"id": "a_00", "trial": "a", "split": "train", "mirror_of": None, "seconds": 2.0, "frames": 40,
            "source": "cmu-amc", "rig": "cmu-amc", "motion_type": "walk", "captions": ["a person walks."],
            "caption_origin": "generated", "description": "walk"}
    (work / "corpus").mkdir()
    (work / "corpus" / "manifest.json").write_text(json.dumps({"clips": [clip]}))
    assert main(["data", "report", "corpus", "--no-crosscheck"]) == 2
    one_error(capsys, "corpus/manifest.json", "clip a_00 lacks licence")


# 4. outputs apart from inputs ----------------------------------------------------------------------------------

def _corpus(folder: Path) -> Path:
    folder.mkdir(parents=True)
    (folder / "train.txt").write_text("a\nb\n")
    for name in ("Mean.npy", "Std.npy"):
        np.save(folder / name, np.ones(263, dtype=np.float32))
    return folder


@pytest.mark.parametrize("out, relation", [("C", "is"), ("C/aug", "lies inside"), (".", "contains"),
                                           ("C/../C", "is")])
def test_augment_refuses_an_out_that_overlaps_the_corpus(work: Path, capsys, out: str, relation: str) -> None:
    corpus = _corpus(work / "C")
    assert main(["data", "augment", "--corpus", "C", "--out", out]) == 2
    one_error(capsys, f"--out {out!r} {relation} --corpus 'C'")
    assert (corpus / "train.txt").read_text() == "a\nb\n"
    assert sorted(p.name for p in corpus.iterdir()) == ["Mean.npy", "Std.npy", "train.txt"]


def test_augment_refuses_an_out_reached_through_a_link(work: Path, capsys) -> None:
    _corpus(work / "C")
    os.symlink(work / "C", work / "link")
    assert main(["data", "augment", "--corpus", "C", "--out", "link"]) == 2
    one_error(capsys, "--out 'link' is --corpus 'C'")


@pytest.mark.parametrize("out", ["shared", "shared/out", "."])
def test_build_refuses_an_out_that_overlaps_shared(work: Path, capsys, out: str) -> None:
    (work / "shared").mkdir()
    assert main(["data", "build", "--shared", "shared", "--out", out, "--quiet"]) == 2
    one_error(capsys, "--shared 'shared'")
    assert list((work / "shared").iterdir()) == []


# 5. track: duplicate outputs, bad inputs ------------------------------------------------------------------------

def test_track_refuses_two_inputs_with_one_output_name(work: Path, capsys) -> None:
    (work / "x").mkdir()
    np.save(work / "x" / "good.npy", np.load(work / "good.npy"))
    assert main(["track", "good.npy", "x/good.npy", "--out", "D"]) == 2
    one_error(capsys, "good.npy and x/good.npy would both be written to D/good.npy")
    assert not (work / "D").exists()


def test_audit_refuses_two_inputs_with_one_output_name(work: Path, capsys) -> None:
    (work / "x").mkdir()
    np.save(work / "x" / "good.npy", np.load(work / "good.npy"))
    assert main(["audit", "good.npy", "x/good.npy", "--out", "D", "--no-track"]) == 2
    one_error(capsys, "D/good_audit.json")
    assert not (work / "D").exists()


def test_track_of_a_degenerate_motion_is_one_plain_line_and_exit_2(work: Path, capsys) -> None:
    np.save(work / "zero.npy", np.zeros((30, 22, 3), dtype=np.float32))
    assert main(["track", "zero.npy"]) == 2
    line = one_error(capsys, "zero.npy", "cannot be tracked")
    assert "Error" not in line


def test_track_reports_each_unreadable_file(work: Path, capsys) -> None:
    np.save(work / "huge.npy", np.full((30, 22, 3), 1e30, dtype=np.float32))
    np.save(work / "one.npy", np.zeros((1, 22, 3), dtype=np.float32) + 5e4)
    assert main(["track", "huge.npy", "one.npy"]) == 2
    _, lines = error_lines(capsys)
    assert len(lines) == 2 and "huge.npy" in lines[0] and "one.npy" in lines[1], lines


# 6. metrics over several files ---------------------------------------------------------------------------------

def test_metrics_prints_the_good_rows_and_one_line_per_bad_file(work: Path, capsys) -> None:
    bad = synthetic.walk().astype(np.float32)
    bad[3, 2, 1] = np.nan
    np.save(work / "nan.npy", bad)
    np.save(work / "onef.npy", synthetic.walk()[:1].astype(np.float32))
    (work / "dir.npy").mkdir()
    files = ["good.npy", "good.npy", "nan.npy", "onef.npy", "dir.npy", "/dev/null"]
    assert main(["metrics", *files]) == 2
    out, lines = error_lines(capsys)
    assert [line.split()[0] for line in out.splitlines()] == ["file", "good.npy", "good.npy"]
    assert len(lines) == 4, lines
    assert "nan.npy" in lines[0] and "non-finite" in lines[0]
    assert "onef.npy" in lines[1] and "at least 2 frames" in lines[1]
    assert "dir.npy: a folder" in lines[2]
    assert "/dev/null: not a regular file" in lines[3]


@pytest.mark.parametrize("name, needle", [("dir.npy", "a folder"), ("/dev/zero", "not a regular file")])
def test_folders_and_devices_say_what_they_are(work: Path, capsys, name: str, needle: str) -> None:
    (work / "dir.npy").mkdir()
    for argv in (["metrics", name], ["convert", name, "o.npy"], ["audit", name, "--no-track"],
                 ["render", name, "--out", "o.png"]):
        assert main(argv) == 2
        one_error(capsys, name, needle)
        assert "no such file" not in needle


# 7. failed runs leave nothing ----------------------------------------------------------------------------------

def test_failed_audit_leaves_no_output_folder(work: Path, capsys) -> None:
    np.save(work / "twof.npy", synthetic.walk()[:2].astype(np.float32))
    assert main(["audit", "twof.npy", "--out", "au3/deeper", "--no-track"]) == 2
    one_error(capsys, "twof.npy")
    assert not (work / "au3").exists()


def test_failed_audit_keeps_the_outputs_of_the_files_done(work: Path, capsys) -> None:
    np.save(work / "twof.npy", synthetic.walk()[:2].astype(np.float32))
    assert main(["audit", "good.npy", "twof.npy", "--out", "au4", "--no-track"]) == 2
    assert (work / "au4" / "good_audit.json").is_file()


def test_build_without_motion_files_leaves_no_output_folder(work: Path, capsys) -> None:
    (work / "f").mkdir()
    assert main(["data", "build", "--shared", "f", "--out", "bd2", "--quiet"]) == 2
    one_error(capsys, "no motion files")
    assert not (work / "bd2").exists()
    (work / "bd3").mkdir()
    assert main(["data", "build", "--shared", "f", "--out", "bd3", "--quiet"]) == 2
    assert (work / "bd3").is_dir() and list((work / "bd3").iterdir()) == []
