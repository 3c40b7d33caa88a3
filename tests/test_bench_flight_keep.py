"""The weak-gravity keep-rate benchmark with and without the re-timed second try (benchmarks/bench_flight_keep.py)."""

from __future__ import annotations

import argparse
import json

import pytest
from benchmark_fixtures import load_benchmark


@pytest.fixture(scope="module")
def bench():
    return load_benchmark("bench_flight_keep")


def test_bins_parse_and_reject_bad_ranges(bench):
    assert bench.parse_bin("-3:-1") == (-3.0, -1.0)
    for bad in ("-1:-3", "x:-1", "-3:0"):
        with pytest.raises(argparse.ArgumentTypeError, match="gravity bin"):
            bench.parse_bin(bad)


def test_tasks_give_both_variants_the_same_g_inside_the_bin(bench):
    ts = bench.tasks([("a", 0.3), ("b", 0.5)], [(-3.0, -1.0), (-5.0, -3.0)], seed=0)
    assert len(ts) == 2 * (1 + 2 * 2)
    for clip in ("a", "b"):
        for b, (lo, hi) in (("g[-3,-1)", (-3, -1)), ("g[-5,-3)", (-5, -3))):
            gs = {t["variant"]: t["g"] for t in ts if t["clip"] == clip and t["bin"] == b}
            assert set(gs) == {"none", "retime"} and gs["none"] == gs["retime"] and lo <= gs["none"] < hi
    assert ts == bench.tasks([("a", 0.3), ("b", 0.5)], [(-3.0, -1.0), (-5.0, -3.0)], seed=0)  # seeded


def test_summary_counts_keeps_retimed_and_flight_ratios(bench, tmp_path):
    def rec(clip, b, v, status="ok", kept=True, scale=1.0, flight=0.3, attempts=1):
        return dict(clip=clip, bin=b, variant=v, g=-2.0, status=status, kept=kept, retime_scale=scale,
                    attempts=attempts, flight_s=flight, pose=5.0, time_warp=scale, cpu_s=1.0, pose_bound=6.557)

    recs = [rec("a", "earth", "none"), rec("b", "earth", "none", flight=0.2),
            rec("a", "g[-3,-1)", "none", status="fell", kept=False), rec("b", "g[-3,-1)", "none", kept=False),
            rec("a", "g[-3,-1)", "retime", scale=2.0, flight=0.9, attempts=2),
            rec("b", "g[-3,-1)", "retime", kept=False, flight=0.6, attempts=2)]
    path = tmp_path / "r.jsonl"
    path.write_text("".join(json.dumps(r) + "\n" for r in recs))
    s = bench.summary(path)
    assert s["clips"] == 2 and s["pose_bound"] == 6.557
    assert s["g[-3,-1) none"]["kept"] == 0 and s["g[-3,-1) none"]["finished"] == 1
    r = s["g[-3,-1) retime"]
    assert (r["kept"], r["kept_retimed"], r["second_tries"]) == (1, 1, 2)
    assert r["flight_vs_earth_median_finished"] == pytest.approx((3.0 + 3.0) / 2)
    lo, hi = r["kept_wilson95"]
    assert 0 < lo < 0.5 < hi < 1
