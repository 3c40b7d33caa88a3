"""The flight-sample keep-rate benchmark (benchmarks/bench_flight_sample.py) on a sample the test writes."""

from __future__ import annotations

import json

import numpy as np
import pytest

from simdiff.errors import SimdiffError
from simdiff.sim.synthetic import standing
from benchmark_fixtures import load_benchmark


@pytest.fixture(scope="module")
def bench():
    return load_benchmark("bench_flight_sample")


def test_keep_rule_scales_the_residual_budget_only_above_earth(bench):
    assert bench.kept("ok", 6.0, 70.0, -1.5)
    assert not bench.kept("fell", 1.0, 1.0, -9.81)
    assert not bench.kept("ok", 6.6, 1.0, -3.0)  # pose bound
    assert not bench.kept("ok", 1.0, 71.0, -5.0)  # budget is 70.6 N below Earth
    assert bench.kept("ok", 1.0, 130.0, -19.62)  # ... and 2 × 70.6 N at 2 g
    assert not bench.kept("ok", float("nan"), 1.0, -9.81)


def test_run_resume_and_summary(bench, tmp_path):
    corpus = tmp_path / "corpus"
    (corpus / "new_joints").mkdir(parents=True)
    np.save(corpus / "new_joints" / "stand.npy", standing(30).astype(np.float32))
    np.save(corpus / "Mean.npy", np.zeros(263, dtype=np.float32))
    np.save(corpus / "Std.npy", np.ones(263, dtype=np.float32))
    sample = tmp_path / "sample.json"
    pairs = [{"clip": "stand", "env": [-9.81, 0.0, 0.0], "group": "earth", "kept_before": True, "status_before": "ok"},
             {"clip": "stand", "env": [-2.0, 0.0, 0.0], "group": "low", "kept_before": False, "status_before": "fell"}]
    sample.write_text(json.dumps(pairs))
    out = tmp_path / "runs.jsonl"
    args = ["--sample", str(sample), "--corpus", str(corpus), "--out", str(out)]
    assert bench.main(args) == 0
    recs = [json.loads(x) for x in out.read_text().splitlines()]
    assert [r["group"] for r in recs] == ["earth", "low"]
    assert all(r["status"] == "ok" and np.isfinite(r["pose"]) for r in recs)  # standing still tracks at any g
    assert bench.main(args) == 0  # resumed: nothing re-run
    assert len(out.read_text().splitlines()) == 2
    s = json.loads(out.with_suffix(".summary.json").read_text())
    assert s["earth"]["pairs"] == 1 and s["low"]["falls_before"] == 1 and s["low"]["falls"] == 0
    assert s["earth"]["kept"] == int(recs[0]["kept"])


def test_unreadable_sample_is_one_line_error(bench, tmp_path):
    bad = tmp_path / "sample.json"
    bad.write_text("{not json")
    with pytest.raises(SimdiffError, match="sample.json"):
        bench.main(["--sample", str(bad), "--corpus", str(tmp_path), "--out", str(tmp_path / "o.jsonl")])
