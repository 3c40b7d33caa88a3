"""benchmarks/bench_generate.py: the environment-guidance comparison runs every value per repeat and reports ratios."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]


def test_env_guidance_values_are_timed_in_turn(tmp_path: Path) -> None:
    from simdiff.serve.testing import write_tiny_model

    out = tmp_path / "bench.json"
    model = write_tiny_model(tmp_path / "model")  # continuous φ, MiniLM by name (as the shipped model)
    cmd = [sys.executable, str(REPO / "benchmarks" / "bench_generate.py"), "--model", str(model),
           "--repeats", "1", "--length", "0.5", "--no-video", "--no-importtime",
           "--env-guidance", "2", "1", "--json", str(out)]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    result = json.loads(out.read_text())
    assert result["command"].endswith("--env-guidance 2")
    rows = result["env_guidance"]
    assert [r["value"] for r in rows] == [2.0, 1.0] and rows[0]["wall_ratio_to_first"] == 1.0
    assert rows[1]["wall_ratio_to_first"] > 0 and len(rows[1]["runs"]) == 1
    assert proc.stderr.count("(env guidance 2)") == 1 and proc.stderr.count("(env guidance 1)") == 1
    bad = subprocess.run([*cmd[:2], "--repeats", "0"], capture_output=True, text=True, timeout=60)
    assert bad.returncode != 0 and "--repeats must be at least 1, got 0" in bad.stderr
