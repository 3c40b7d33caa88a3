"""``simdiff generate`` option validation (no torch, no model): lengths, φ, --compare, --format, steps."""

from __future__ import annotations

import math
import subprocess
import sys

import pytest

from simdiff.diffusion.config import SamplingConfig
from simdiff.errors import SimdiffError
from simdiff.product.request import (
    MAX_FRAMES, build_request, check_text, environments, frames_from, parse_compare, parse_formats,
)


def test_defaults_match_the_readme_command() -> None:
    r = build_request("  a person   jumps forward ", gravity=-3.7, wind=(2.0, 0.0))
    assert r.text == "a person jumps forward"
    assert (r.frames, r.seconds, r.seed, r.sampling) == (120, 6.0, 0, SamplingConfig())
    assert [e.as_tuple() for e in r.envs] == [(-3.7, 2.0, 0.0)] and r.compare is None
    assert r.formats == ("npy", "bvh", "gif") and r.video_formats == ("gif",)
    assert build_request("walk").envs[0].as_tuple() == (-9.81, 0.0, 0.0)


def test_max_frames_matches_the_generator() -> None:
    from simdiff.inference.generator import MAX_FRAMES as GENERATOR_MAX

    assert MAX_FRAMES == GENERATOR_MAX == 196


@pytest.mark.parametrize("seconds, frames", [(6, 120), (9.8, 196), (0.5, 10), (2.52, 50)])
def test_length_in_seconds_to_frames(seconds: float, frames: int) -> None:
    assert frames_from(length_s=seconds) == frames


@pytest.mark.parametrize("kwargs, needle", [
    ({"length_s": 9.9}, "198 frames"), ({"length_s": 0.0}, "0 frames"), ({"length_s": math.nan}, "nan"),
])
def test_bad_lengths(kwargs: dict, needle: str) -> None:
    with pytest.raises(SimdiffError, match=needle):
        frames_from(**kwargs)


@pytest.mark.parametrize("text", ["", "   ", "\n\t"])
def test_blank_text(text: str) -> None:
    with pytest.raises(SimdiffError, match="empty"):
        check_text(text)


def test_compare_spec() -> None:
    assert parse_compare("gravity=-9.81,-3.7,-1.6") == ("gravity", (-9.81, -3.7, -1.6))
    assert parse_compare("wind-x=0, 5,10") == ("wind_x", (0.0, 5.0, 10.0))
    envs = environments(-3.7, (1.0, 2.0), parse_compare("wind_y=-4,4"))
    assert [e.as_tuple() for e in envs] == [(-3.7, 1.0, -4.0), (-3.7, 1.0, 4.0)]


@pytest.mark.parametrize("spec, needle", [
    ("gravity", "expected gravity="), ("mass=1,2", "expected gravity="), ("gravity=-1,abc", "'abc'"),
    ("gravity=-1", "got 1"), ("gravity=-1,-1", "repeated"), ("wind_x=1,inf", "'inf'"),
    ("gravity=" + ",".join(str(-i) for i in range(1, 11)), "got 10"),
])
def test_bad_compare_spec(spec: str, needle: str) -> None:
    with pytest.raises(SimdiffError, match=needle) as info:
        parse_compare(spec)
    assert spec.split(",")[0] in str(info.value) and "\n" not in str(info.value)


@pytest.mark.parametrize("gravity, wind, needle", [
    (0.0, (0.0, 0.0), "gravity must be negative"), (3.0, (0.0, 0.0), "got 3.0"), (math.nan, (0.0, 0.0), "--gravity"),
    (-math.inf, (0.0, 0.0), "--gravity"), (-9.81, (math.nan, 0.0), "--wind X"), (-9.81, (11.0, 0.0), "11 N"),
    (-9.81, (8.0, 8.0), "11.3 N"), (-30.0, (0.0, 0.0), "-30.0"),
])
def test_bad_environments(gravity: float, wind: tuple[float, float], needle: str) -> None:
    with pytest.raises(SimdiffError, match=needle):
        environments(gravity, wind, None)


def test_force_allows_out_of_range_but_not_positive_gravity() -> None:
    assert environments(-30.0, (20.0, 0.0), None, force=True)[0].as_tuple() == (-30.0, 20.0, 0.0)
    with pytest.raises(SimdiffError, match="negative"):
        environments(0.5, (0.0, 0.0), None, force=True)
    with pytest.raises(SimdiffError, match="20 N"):
        environments(-9.81, (0.0, 0.0), parse_compare("wind_x=0,20"))


def test_request_numbers() -> None:
    with pytest.raises(SimdiffError, match="--num-samples must be 1..64, got 0"):
        build_request("walk", num_samples=0)
    with pytest.raises(SimdiffError, match="--seed must be in 0..4294967295, got -2"):
        build_request("walk", seed=-2)


def test_formats() -> None:
    assert parse_formats("bvh, MP4,bvh") == ("bvh", "mp4")
    assert parse_formats(None) == ("npy", "bvh", "gif")
    with pytest.raises(SimdiffError, match="'avi'"):
        parse_formats("npy,avi")
    with pytest.raises(SimdiffError, match="nothing to write"):
        parse_formats(" , ")


def test_validation_errors_do_not_import_torch() -> None:
    code = ("import sys\nfrom simdiff.cli.main import main\nrc = main(['generate', ' ', '--format', 'npy'])\n"
            "assert 'torch' not in sys.modules, 'torch imported'\nsys.exit(rc)")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert proc.returncode == 2, proc.stderr
    assert proc.stderr.strip().splitlines() == [
        'simdiff: error: the text prompt is empty; describe the motion, e.g. "a person jumps forward"']
