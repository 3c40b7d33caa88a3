"""``generate --timeline``: segments checked one line each, sampled one after another into one motion."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from simdiff.cli.main import main
from simdiff.errors import SimdiffError
from simdiff.inference.timeline import CONTEXT_FRAMES, segment_seed, spans
from simdiff.product.request import parse_timeline
from simdiff.train.testing import tiny_generator

pytestmark = pytest.mark.usefixtures("one_torch_thread")

GOOD = [{"text": "a person walks forward", "seconds": 1.0},
        {"text": "a person jumps", "seconds": 0.5, "gravity": -1.6},
        {"text": "a person walks forward", "seconds": 0.6, "wind": [0, 5]}]


def test_a_good_timeline_parses_into_segments() -> None:
    segments = parse_timeline(GOOD)
    assert [(s.text, s.frames) for s in segments] == [("a person walks forward", 20), ("a person jumps", 10),
                                                      ("a person walks forward", 12)]
    assert segments[1].env.gravity == -1.6 and segments[2].env.as_tuple() == (-9.81, 0.0, 5.0)
    assert spans(segments) == [(0, 20), (20, 30), (30, 42)]
    assert len({segment_seed(s, i) for s in range(5) for i in range(5)}) == 25


@pytest.mark.parametrize("data, needle", [
    ([], "non-empty JSON list"),
    ({"text": "x"}, "non-empty JSON list"),
    (["walk"], "segment 0 is str"),
    ([{"text": "a person walks"}], "segment 0 has no 'seconds'"),
    ([{"text": "a person walks", "seconds": 2, "speed": 1}], "unknown key 'speed'"),
    ([{"text": "", "seconds": 2}], "segment 0: the text prompt is empty"),
    ([{"text": 3, "seconds": 2}], "text must be a string"),
    ([{"text": "a person walks", "seconds": "2"}], "seconds must be a number"),
    ([{"text": "a person walks", "seconds": 30}], "seconds 30 is outside 0.5..9.8"),
    ([GOOD[0], {"text": "a person runs", "seconds": 9.8}], "segment 1: seconds 9.8 is outside 0.05..9.3"),
    ([GOOD[0], {"text": "a person runs", "seconds": 2, "gravity": 3}], "segment 1: gravity must be negative"),
    ([GOOD[0], {"text": "a person runs", "seconds": 2, "gravity": -50}], "segment 1: gravity -50"),
    ([GOOD[0], {"text": "a person runs", "seconds": 2, "wind": [1]}], "wind must be [x, y]"),
    ([GOOD[0], {"text": "a person runs", "seconds": 2, "wind": [1, True]}], "wind must be a number"),
    ([GOOD[0], {"text": "a person runs", "seconds": float("nan")}], "seconds must be a finite number"),
    ([{"text": "a person walks", "seconds": 1e308}], "seconds 1e+308 is outside"),
    ([{"text": "a person walks", "seconds": 10**400}], "seconds must be a finite number, got an integer of 401 digits"),
    ([{"text": "a person walks", "seconds": 2, "gravity": -(10**400)}], "gravity must be a finite number"),
])
def test_bad_segments_are_named(data, needle: str) -> None:
    with pytest.raises(SimdiffError, match=None) as info:
        parse_timeline(data, "t.json")
    assert needle in str(info.value) and "\n" not in str(info.value), str(info.value)


@pytest.fixture(scope="module")
def tiny_model(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("tiny_timeline")
    tiny_generator().save(folder)
    return folder


def test_generate_timeline_writes_one_motion(tiny_model: Path, tmp_path: Path, capsys) -> None:
    (tmp_path / "t.json").write_text(json.dumps(GOOD))
    assert main(["generate", "--timeline", str(tmp_path / "t.json"), "--steps", "3", "--model", str(tiny_model),
                 "--format", "npy", "--out", str(tmp_path / "o"), "-q"]) == 0, capsys.readouterr().err
    joints = np.load(tmp_path / "o" / "sample0_joints.npy")
    assert joints.shape == (42, 22, 3) and np.load(tmp_path / "o" / "sample0_features.npy").shape == (42, 263)
    meta = json.loads((tmp_path / "o" / "generation.json").read_text())
    assert meta["frames"] == 42 and meta["environment"] is None
    assert [s["frames"] for s in meta["timeline"]] == [[0, 20], [20, 30], [30, 42]]
    assert meta["timeline"][1]["environment"]["gravity"] == -1.6
    assert meta["prompt"].startswith("a person walks forward, then a person jumps")
    step = np.linalg.norm(np.diff(joints[:, 0], axis=0), axis=-1)
    seams = [20 - 1, 30 - 1]
    assert CONTEXT_FRAMES == 10 and step[seams].max() < 0.2  # no root jump where a segment starts


@pytest.mark.parametrize("extra, needle", [
    (["a person walks"], "leave TEXT out"),
    (["--simulate"], "leave --simulate out"),
    (["--gravity", "-3.7"], "leave --gravity out"),
    (["--length", "2"], "leave --length out"),
])
def test_generate_timeline_conflicts_get_one_line(extra: list[str], needle: str, tiny_model: Path, tmp_path: Path,
                                                  capsys) -> None:
    (tmp_path / "t.json").write_text(json.dumps(GOOD))
    assert main(["generate", *extra, "--timeline", str(tmp_path / "t.json"), "--model", str(tiny_model)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and needle in err, err


def test_generate_bad_timeline_files_get_one_line(tmp_path: Path, capsys) -> None:
    (tmp_path / "bad.json").write_text("[{oops")
    assert main(["generate", "--timeline", str(tmp_path / "bad.json")]) == 2
    assert "not a JSON timeline" in capsys.readouterr().err
    assert main(["generate", "--timeline", str(tmp_path / "none.json")]) == 2
    assert "none.json" in capsys.readouterr().err
    assert main(["generate"]) == 2
    assert "TEXT" in capsys.readouterr().err
