"""benchmarks/bench_speed.py: the three speed ratios are measured in one run and written as JSON."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]


def test_speed_benchmark_prints_and_writes_every_ratio(tmp_path: Path) -> None:
    from simdiff.serve.testing import write_tiny_model

    model = write_tiny_model(tmp_path / "model")  # 3 runs per side: one cold start alone once read 0.97 in CI
    (model / "sampling.json").write_text('{"steps": 4, "guidance": 2.0, "guidance_min_t": 500}')
    out = tmp_path / "speed.json"
    cmd = [sys.executable, str(REPO / "benchmarks" / "bench_speed.py"), "--model", str(model), "--repeats", "3",
           "--length", "1", "--json", str(out)]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=600, cwd=REPO)
    assert proc.returncode == 0, proc.stderr
    result = json.loads(out.read_text())
    assert [r["gravity"] for r in result["sampling"]] == [-9.81, -1.6]
    assert all(r["default"] == "ddim-4" and 0 < r["ratio"] < 1 for r in result["sampling"])  # 4 steps against 50
    assert result["cold_generate"]["ratio"] > 1 and result["cold_generate"]["stages_s"]["sample"] > 0
    assert result["warm_viewer"]["request_s"] > 0
    assert proc.stdout.count("target") == 4
    bad = subprocess.run(cmd[:2] + ["--repeats", "0"], capture_output=True, text=True, timeout=60)
    assert bad.returncode != 0 and "--repeats must be at least 1, got 0" in bad.stderr
