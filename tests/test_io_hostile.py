"""Motion readers under hostile input: every bad file or rate is one line naming the file, never a traceback."""

from __future__ import annotations

import json
import pickle
from pathlib import Path

import numpy as np
import pytest

from simdiff.errors import MotionFormatError, SimdiffError
from simdiff.motion.io import load_joints, load_rig
from simdiff.motion.io.bvh import MAX_DEPTH, parse_bvh, read_bvh
from simdiff.motion.io.deepmimic import VALUES_PER_FRAME, read_deepmimic
from simdiff.motion.io.npy import read_npy
from simdiff.motion.io.resample import resample

HEAD = """HIERARCHY
ROOT Hips
{
  OFFSET 0 0 0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
  JOINT Chest
  {
    OFFSET 0 10 0
    CHANNELS 3 Xrotation Yrotation Zrotation
    End Site
    {
      OFFSET 0 5 0
    }
  }
}
MOTION
"""
ROW = "0 0 0 0 0 0 0 0 0\n"


def _bvh(tmp_path: Path, frames: str = "Frames: 2", frame_time: str = "Frame Time: 0.0333333",
         rows: str = ROW * 2, head: str = HEAD, name: str = "take.bvh") -> Path:
    path = tmp_path / name
    path.write_text(f"{head}{frames}\n{frame_time}\n{rows}")
    return path


def _one_line(exc: pytest.ExceptionInfo[BaseException], *parts: str) -> str:
    message = str(exc.value)
    assert "\n" not in message and len(message) < 400, message
    for part in parts:
        assert part in message, message
    return message


@pytest.mark.parametrize("value", ["nan", "0", "-0.01", "inf", "1e-300", "-inf", "1e-9"])
def test_bvh_bad_frame_time_is_one_line_naming_file_line_and_value(tmp_path: Path, value: str) -> None:
    path = _bvh(tmp_path, frame_time=f"Frame Time: {value}")
    line = HEAD.count("\n") + 2
    with pytest.raises(MotionFormatError) as exc:
        read_bvh(path)
    _one_line(exc, f"{path}:{line}", "Frame Time", f"{float(value):g}")
    with pytest.raises(MotionFormatError):
        load_joints(path)


@pytest.mark.parametrize("frames", ["nan", "inf", "1e400", "-3", "2.5", "1e12", "99999999999999999999"])
def test_bvh_bad_or_huge_frame_count(tmp_path: Path, frames: str) -> None:
    path = _bvh(tmp_path, frames=f"Frames: {frames}")
    with pytest.raises(MotionFormatError) as exc:
        parse_bvh(path)
    _one_line(exc, str(path))


def _deep_bvh(depth: int) -> str:
    lines = ["HIERARCHY", "ROOT j0", "{", "OFFSET 0 0 0", "CHANNELS 3 Xposition Yposition Zposition"]
    for k in range(1, depth):
        lines += [f"JOINT j{k}", "{", "OFFSET 0 1 0", "CHANNELS 1 Xrotation"]
    lines += ["}"] * depth
    return "\n".join(lines) + f"\nMOTION\nFrames: 1\nFrame Time: 0.01\n{' '.join(['0'] * (depth + 2))}\n"


def test_bvh_nested_5000_deep_is_refused_in_one_line(tmp_path: Path) -> None:
    path = tmp_path / "deep.bvh"
    path.write_text(_deep_bvh(5000))
    with pytest.raises(MotionFormatError) as exc:
        parse_bvh(path)
    _one_line(exc, str(path), f"deeper than {MAX_DEPTH} joints")
    ok = tmp_path / "ok.bvh"
    ok.write_text(_deep_bvh(MAX_DEPTH))
    assert len(parse_bvh(ok).joints) == MAX_DEPTH


@pytest.mark.parametrize("rows, frames, what", [
    (ROW * 2, "Frames: 5", "truncated"),
    ("0 0 0 0 0 0 0 0\n" * 2, "Frames: 2", "values"),  # fewer values than channels
    ("0 0 0 0 0 0 0 0 0 0\n" * 2, "Frames: 2", "values"),  # more
    ("0 0 0 abc 0 0 0 0 0\n" * 2, "Frames: 2", "non-numeric"),
    ("0 0 0 inf 0 0 0 0 0\n" * 2, "Frames: 2", "non-finite"),
    ("0 0 0 nan 0 0 0 0 0\n" * 2, "Frames: 2", "non-finite"),
    ("0 0 0 1e999 0 0 0 0 0\n" * 2, "Frames: 2", "non-finite"),
    ("", "Frames: 0", "no frames"),
    ("x" * 10_000_000 + "\n", "Frames: 1", "values"),
])
def test_bvh_bad_motion_data(tmp_path: Path, rows: str, frames: str, what: str) -> None:
    path = _bvh(tmp_path, frames=frames, rows=rows)
    with pytest.raises(MotionFormatError) as exc:
        load_joints(path)
    _one_line(exc, str(path), what)


@pytest.mark.parametrize("content", [b"", b"\x00\xff\xfe" * 1000 + b"\x89PNG", b"HIERARCHY\n" + b"ROOT " + b"y" * 10_000_000,
                                     b"HIERARCHY\nROOT a\n{\nOFFSET 0 0 0\nCHANNELS 99999999999999999999999 X\n}\n",
                                     b"HIERARCHY\nROOT a\n{\nOFFSET 0 0 0\nCHANNELS \xc2\xb2 X\n}\n"])
def test_bvh_garbage_files(tmp_path: Path, content: bytes) -> None:
    path = tmp_path / "junk.bvh"
    path.write_bytes(content)
    with pytest.raises(MotionFormatError) as exc:
        load_joints(path)
    _one_line(exc, str(path))


def _dm_frame(dt: float = 1 / 30) -> list[float]:
    q = [1.0, 0.0, 0.0, 0.0]
    return [dt, 0.0, 0.9, 0.0, *q, *q, *q, *q, 0.0, *q, *q, 0.0, *q, 0.0, *q, *q, 0.0]


@pytest.mark.parametrize("text, what", [
    ('{"Loop": "none", "Frames": ' + "[" * 5000 + "]" * 5000 + "}", "nested too deeply"),
    ("[" * 100_000, "nested too deeply"),
    ('{"Frames": [[' + "1" * 5000 + "]]}", "digits"),
    ('{"Frames": [[' + ", ".join(["1" + "0" * 400] * VALUES_PER_FRAME) + "]]}", "finite numbers"),
    ('{"Frames": [' + ", ".join([json.dumps(_dm_frame(1e-9))] * 3) + "]}", "frame rate"),
    ('{"Frames": [' + ", ".join([json.dumps(_dm_frame()), json.dumps(_dm_frame(1e9)), json.dumps(_dm_frame())]) + "]}",
     "frame durations add up"),
    ("", "invalid JSON"),
    ("\x00\x01garbage", "invalid JSON"),
])
def test_deepmimic_hostile_json(tmp_path: Path, text: str, what: str) -> None:
    path = tmp_path / "clip.txt"
    path.write_text(text)
    with pytest.raises(MotionFormatError) as exc:
        read_deepmimic(path)
    _one_line(exc, str(path), what)


def _npy_header(path: Path, shape: tuple[int, ...], descr: str = "<f4", data: bytes = b"\0" * 64) -> Path:
    with open(path, "wb") as handle:
        np.lib.format.write_array_header_1_0(handle, {"descr": descr, "fortran_order": False, "shape": shape})
        handle.write(data)
    return path


def test_npy_hostile_files_are_one_line_without_python_hints(tmp_path: Path) -> None:
    text = tmp_path / "text.npy"
    text.write_text("just some text\n")
    pickled = tmp_path / "pickled.npy"
    pickled.write_bytes(pickle.dumps({"a": 1}))
    objects = tmp_path / "objects.npy"
    np.save(objects, np.array([{"a": 1}, None], dtype=object), allow_pickle=True)
    empty = tmp_path / "empty.npy"
    empty.write_bytes(b"")
    huge = _npy_header(tmp_path / "huge.npy", (10**12, 22, 3))
    complex_ = tmp_path / "complex.npy"
    np.save(complex_, np.zeros((4, 22, 3), dtype=complex))
    big = tmp_path / "big.npy"
    np.save(big, np.full((4, 22, 3), 1e300))
    cases = {text: "not a NumPy .npy array file", pickled: "not a NumPy .npy array file",
             objects: "holds Python objects, not numbers", empty: "not a NumPy .npy array file",
             huge: "the file holds less data", complex_: "not real numbers", big: "non-finite"}
    for path, what in cases.items():
        for reader in (read_npy, load_joints):
            with pytest.raises(MotionFormatError) as exc:
                reader(path)
            message = _one_line(exc, str(path), what)
            assert "allow_pickle" not in message and "=" not in message


def test_amc_without_asf_speaks_cli(tmp_path: Path) -> None:
    amc = tmp_path / "07_01.amc"
    amc.write_text(":FULLY-SPECIFIED\n:DEGREES\n1\nroot 0 0 0 0 0 0\n")
    with pytest.raises(MotionFormatError) as exc:
        load_joints(amc)
    message = _one_line(exc, str(amc), "pass --asf FILE")
    assert "asf=" not in message
    with pytest.raises(MotionFormatError) as exc:
        load_joints(_bvh(tmp_path).with_suffix(".npy"), units="cm")
    assert "units=" not in str(exc.value)


BAD_RATES = [0.0, -5.0, float("nan"), float("inf"), -float("inf"), 1e300, 1000.5, "fast"]


@pytest.mark.parametrize("fps", BAD_RATES)
def test_library_fps_arguments_are_checked(tmp_path: Path, fps: object) -> None:
    bvh = _bvh(tmp_path)
    npy = tmp_path / "joints.npy"
    np.save(npy, np.zeros((4, 22, 3), dtype=np.float32))
    dm = tmp_path / "clip.txt"
    dm.write_text(json.dumps({"Frames": [_dm_frame(), _dm_frame()]}))
    calls = [lambda: resample(np.zeros((4, 3)), fps, 20.0), lambda: resample(np.zeros((4, 3)), 20.0, fps),
             lambda: load_joints(bvh, fps=fps), lambda: load_joints(npy, fps=fps), lambda: load_rig(bvh, fps=fps),
             lambda: read_bvh(bvh, fps=fps), lambda: read_deepmimic(dm, fps=fps)]
    for call in calls:
        with pytest.raises(SimdiffError) as exc:
            call()
        _one_line(exc, "[1, 1000] Hz")
    with pytest.raises(ValueError):  # still a ValueError for callers that catch that
        resample(np.zeros((4, 3)), fps, 20.0)


def test_amc_rates_from_files_are_checked(tmp_path: Path) -> None:
    from simdiff.motion.io.asf_amc import lookup_cmu_fps, read_amc

    (tmp_path / "CMU_data.csv").write_text("Subject,Trial #,framerate\n7,1,nan\n7,2,120\n7,3,-60\n")
    with pytest.raises(MotionFormatError) as exc:
        lookup_cmu_fps(tmp_path / "07_01.amc")
    _one_line(exc, "CMU_data.csv", "nan")
    assert lookup_cmu_fps(tmp_path / "07_02.amc") == 120.0
    with pytest.raises(MotionFormatError):
        lookup_cmu_fps(tmp_path / "07_03.amc")
    assert lookup_cmu_fps(tmp_path / "\u00b2_\u00b3.amc") is None
    with pytest.raises(SimdiffError, match="1000"):
        read_amc(tmp_path / "07_02.amc", tmp_path / "none.asf", fps=float("inf"))


def test_bvh_folder_readme_rate_is_checked(tmp_path: Path) -> None:
    (tmp_path / "salsa").mkdir()
    path = _bvh(tmp_path / "salsa")
    (tmp_path / "readme.txt").write_text("salsa framerate 99999\n")
    with pytest.raises(MotionFormatError) as exc:
        load_rig(path)
    _one_line(exc, "readme.txt:1", "99999")
    (tmp_path / "readme.txt").write_text("salsa framerate 60\n")
    assert load_rig(path).fps == 60.0


ASF = (":units\n  length 0.45\n:root\n  order TX TY TZ RX RY RZ\n  axis XYZ\n  orientation 0 0 0\n"
       ":bonedata\n  begin\n    name a\n    direction 0 1 0\n    length 1\n    axis 0 0 0 XYZ\n  end\n"
       ":hierarchy\n  begin\n    root a\n  end\n")


def test_amc_frame_numbers_are_ascii_and_short(tmp_path: Path) -> None:
    asf = tmp_path / "07.asf"
    asf.write_text(ASF)
    for number in ("\u00b2", "1" * 5000):
        amc = tmp_path / "07_01.amc"
        amc.write_text(f":DEGREES\n{number}\nroot 0 0 0 0 0 0\n")
        with pytest.raises(MotionFormatError) as exc:
            load_joints(amc, asf=asf)
        _one_line(exc, str(amc))


def test_bvh_values_that_overflow_the_positions(tmp_path: Path) -> None:
    path = _bvh(tmp_path, rows="1e308 1e308 0 0 0 0 0 0 0\n" * 2, head=HEAD.replace("OFFSET 0 10 0", "OFFSET 0 1e308 0"))
    with pytest.raises(MotionFormatError) as exc:
        read_bvh(path, scale=1.0)
    _one_line(exc, str(path), "overflow")


def test_deepmimic_positions_that_overflow(tmp_path: Path) -> None:
    frame = _dm_frame()
    frame[1:4] = [1e299, 1e299, 1e299]
    path = tmp_path / "clip.txt"
    path.write_text(json.dumps({"Frames": [frame, frame]}))
    with pytest.raises(MotionFormatError) as exc:
        read_deepmimic(path)
    _one_line(exc, str(path))


def test_amc_positions_that_overflow(tmp_path: Path) -> None:
    from simdiff.motion.io.asf_amc import read_amc

    asf = tmp_path / "07.asf"
    asf.write_text(ASF)
    amc = tmp_path / "07_01.amc"
    amc.write_text(":DEGREES\n1\nroot 1e308 0 0 0 0 0\n")
    with pytest.raises(MotionFormatError) as exc:
        read_amc(amc, asf)
    _one_line(exc, str(amc), "overflow")
