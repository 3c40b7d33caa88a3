"""The ``simdiff`` command: discovery, help, one-line errors, convert/metrics end to end."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from simdiff.cli.main import build_parser, main
from simdiff.motion import synthetic
from simdiff.motion.features import joints_to_features


def test_every_command_is_discovered():
    parser = build_parser()
    sub = next(a for a in parser._actions if a.dest == "command")
    for name in ("convert", "metrics", "render", "generate", "track", "train", "sample", "data"):
        assert name in sub.choices


def test_convert_joints_features_bvh_round_trip(tmp_path: Path, capsys):
    joints = synthetic.walk(30)
    np.save(tmp_path / "walk.npy", joints)
    assert main(["convert", str(tmp_path / "walk.npy"), str(tmp_path / "f.npy"), "--to", "features"]) == 0
    feats = np.load(tmp_path / "f.npy")
    np.testing.assert_allclose(feats, joints_to_features(joints), atol=1e-6)
    assert main(["convert", str(tmp_path / "f.npy"), str(tmp_path / "w.bvh")]) == 0
    assert main(["convert", str(tmp_path / "w.bvh"), str(tmp_path / "back.npy")]) == 0
    back = np.load(tmp_path / "back.npy")
    assert back.shape == (29, 22, 3)


def test_metrics_json(tmp_path: Path, capsys):
    joints = synthetic.walk(30).copy()
    joints[..., 1] += 0.02  # hovering 2 cm: floating = 20 - 5 mm on every frame
    np.save(tmp_path / "hover.npy", joints)
    assert main(["metrics", str(tmp_path / "hover.npy"), "--json"]) == 0
    row = json.loads(capsys.readouterr().out.strip())
    assert row["frames"] == 30 and row["penetration"] == 0.0
    lowest = joints[..., 1].min(axis=1)
    assert row["floating"] == pytest.approx(float(np.mean(np.maximum(lowest - 0.005, 0)) * 1000), rel=1e-5)
    assert row["never_touch"] == 0
    joints[..., 1] += 0.5  # half a metre up all clip long
    np.save(tmp_path / "afloat.npy", joints)
    assert main(["metrics", str(tmp_path / "afloat.npy"), str(tmp_path / "hover.npy")]) == 0
    table = capsys.readouterr().out.splitlines()
    assert "never_touch" in table[0] and table[1].split()[-1] == "1" and table[2].split()[-1] == "0"


@pytest.mark.parametrize(
    "argv, needle",
    [
        (["convert", "missing.amc", "x.npy"], "missing.amc"),
        (["convert", "{tmp}/w.npy", "{tmp}/x.txt"], "x.txt"),
        (["metrics", "{tmp}/bad.npy"], "bad.npy"),
    ],
)
def test_bad_input_gives_one_line_error(tmp_path: Path, argv, needle):
    np.save(tmp_path / "w.npy", synthetic.walk(5))
    np.save(tmp_path / "bad.npy", np.zeros((5, 7)))
    argv = [a.format(tmp=tmp_path) for a in argv]
    proc = subprocess.run([sys.executable, "-m", "simdiff", *argv], capture_output=True, text=True, cwd=tmp_path)
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("simdiff: error:") and needle in lines[0]


def test_generate_names_a_missing_model(tmp_path: Path, capsys):
    code = main(["generate", "a person jumps forward", "--model", str(tmp_path / "nowhere"), "--out", str(tmp_path / "o")])
    assert code == 2
    assert "nowhere/config.json: model file not found" in capsys.readouterr().err


def test_parsers_can_be_built_repeatedly():
    import gc

    for _ in range(5):  # group registration must not leak between parsers (ids get reused)
        build_parser()
        gc.collect()
    assert build_parser().parse_args(["data", "report", "x"]).command == "data"
