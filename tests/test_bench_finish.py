"""The simulated finish's tracking benchmark (benchmarks/bench_finish.py): summary and a run on kept samples."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from benchmark_fixtures import load_benchmark


@pytest.fixture(scope="module")
def bench():
    return load_benchmark("bench_finish")


def test_summary_counts_tracked_and_sliding_per_kind(bench):
    rows = [{"kind": "walks", "status": "ok", "sliding_simulated": 1.0, "attempts": 2, "fallback": False},
            {"kind": "walks", "status": "fell", "sliding_simulated": 0.2, "attempts": 2, "fallback": True},
            {"kind": "jumps", "status": "ok", "sliding_simulated": 0.1},
            {"kind": "jumps", "status": "ok", "sliding_simulated": None}]
    s = bench.summarize(rows)
    assert s["walks"] == {"n": 2, "tracked": 1, "second_tries": 2, "fallback_kept": 1, "sliding_within_0.5": 1,
                          "sliding_mean_tracked": 1.0}
    assert s["jumps"] == {"n": 2, "tracked": 2, "second_tries": 0, "fallback_kept": 0, "sliding_within_0.5": 1,
                          "sliding_mean_tracked": pytest.approx(0.1)}
    assert s["all"]["n"] == 4 and s["all"]["tracked"] == 3 and s["all"]["sliding_mean_tracked"] == pytest.approx(0.55)


def test_a_kept_sample_is_finished_without_generating_again(bench, tmp_path: Path, monkeypatch) -> None:
    pytest.importorskip("mujoco")
    import simdiff.sim.fallback as fallback

    monkeypatch.setattr(fallback, "FINISH_FALLBACK", True)  # restored after the --no-fallback run below
    from simdiff.sim.synthetic import standing

    work = tmp_path / "work"
    (work / "s0_p0_g0").mkdir(parents=True)
    np.save(work / "s0_p0_g0" / "sample0_joints.npy", standing(30).astype(np.float32))
    out = tmp_path / "finish.json"
    assert bench.main(["--prompts", "a person stands still", "--gravities", "-9.81", "--seeds", "0",
                       "--work", str(work), "--json", str(out)]) == 0
    report = json.loads(out.read_text())
    (row,) = report["rows"]
    assert row["status"] == "ok" and row["kind"] == "stands" and row["sliding_simulated"] < 0.5
    assert report["summary"]["all"] == {"n": 1, "tracked": 1, "second_tries": 0, "fallback_kept": 0,
                                        "sliding_within_0.5": 1,
                                        "sliding_mean_tracked": pytest.approx(row["sliding_simulated"])}
    assert row["attempts"] == 1 and not row["fallback"] and not report["no_fallback"]  # a quiet stand: one try
    assert bench.main(["--prompts", "a person stands still", "--gravities", "-9.81", "--seeds", "0",
                       "--work", str(work), "--json", str(out), "--no-fallback"]) == 0
    assert json.loads(out.read_text())["no_fallback"] is True
    with pytest.raises(SystemExit):
        bench.main(["--lead", "-1", "--work", str(work)])
    with pytest.raises(SystemExit):
        bench.main(["--moving-kp-xy", "nan", "--work", str(work)])
    with pytest.raises(SystemExit):
        bench.main(["--late-foot", "stay", "--work", str(work)])
    with pytest.raises(SystemExit):
        bench.main(["--moving-rot-scale", "1.5", "--work", str(work)])
