"""The `--simulate` benchmark's summary (benchmarks/bench_simulate.py): targets counted, second tries counted."""

from __future__ import annotations

import pytest
from benchmark_fixtures import load_benchmark


def test_summary_counts_targets_tracking_and_second_tries():
    bench = load_benchmark("bench_simulate")
    rows = [{"added_wall_s": 0.6, "added_cpu_s": 2.0, "sliding_simulated": 0.2, "status": "ok", "attempts": 1,
             "fallback": False},
            {"added_wall_s": 1.1, "added_cpu_s": 2.4, "sliding_simulated": 0.48, "status": "ok", "attempts": 2,
             "fallback": True},
            {"added_wall_s": 2.5, "added_cpu_s": 3.0, "sliding_simulated": 0.7, "status": "fell", "attempts": 2,
             "fallback": False},
            {"added_wall_s": 0.9, "added_cpu_s": 2.1, "sliding_simulated": None, "status": "ok"}]  # an older row
    s = bench.summarize(rows)
    assert s["n"] == 4 and s["added_wall_s_max"] == 2.5 and s["added_wall_s_median"] == 1.1
    assert s["added_within_2_s"] == 3 and s["sliding_within_0.5"] == 2 and s["tracked"] == 3
    assert s["sliding_simulated_max"] == pytest.approx(0.7) and s["added_cpu_s_max"] == 3.0
    assert s["second_tries"] == 2 and s["fallback_kept"] == 1
