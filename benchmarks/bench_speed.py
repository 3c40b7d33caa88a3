"""Interactive speed, as three ratios measured in one run on this machine.

Usage::

    python benchmarks/bench_speed.py [--model DIR] [--repeats 5] [--length 6] [--json out.json]

1. **Sampling**: the model's default sampler (its ``sampling.json``) against DDIM-50 of the same model, same prompt,
   seed and φ (Earth, then Moon gravity, where the edit setting adds passes), in one process, batch 1, the two
   timed in turn; ratio of the medians. Target ≤ 0.2.
2. **Cold generate**: ``python -m simdiff generate TEXT --format bvh`` (a 6 s jump written as BVH) in a fresh
   interpreter against a bare ``python -c "import torch"``, timed in turn; ratio of the medians. Target ≤ 1.6.
3. **Warm viewer**: the viewer's server on a free local port, after one warm-up request; median seconds of a
   ``POST /api/generate`` of a 6 s motion, as a ratio to 0.5 s. Target ≤ 1.

Timing each pair in turn means a change of load hits both sides alike; the ratios are the claims, the seconds
depend on the machine. Without ``--model`` the shipped default model is used.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
import urllib.request
from pathlib import Path

TEXT = "a person jumps forward"
TARGETS = {"sampling": 0.2, "cold_generate": 1.6, "warm_viewer": 1.0}
VIEWER_BUDGET_S = 0.5


def _median_pair(run_a, run_b, repeats: int) -> tuple[list[float], list[float]]:
    """Seconds of ``run_a()`` and ``run_b()``, alternated ``repeats`` times."""
    a, b = [], []
    for _ in range(repeats):
        for fn, out in ((run_a, a), (run_b, b)):
            start = time.perf_counter()
            fn()
            out.append(time.perf_counter() - start)
    return a, b


def sampling_ratio(model: Path, frames: int, repeats: int) -> list[dict]:
    """Default sampler against DDIM-50, at Earth and at g −1.6 (rows of seconds and ratios)."""
    import torch

    from simdiff.inference.default import sampling_config
    from simdiff.inference.generator import MotionGenerator

    gen = MotionGenerator.load(model, device=torch.device("cpu"))
    default = sampling_config(model)
    ddim = default.updated(sampler="ddim", steps=50)
    text = gen.encode_text([TEXT])
    rows = []
    for gravity in (-9.81, -1.6):
        env = (gravity, 0.0, 0.0) if gen.is_simdiff else None

        def run(config):
            return lambda: gen.generate([TEXT], frames, config, env=env, seed=0, text_embeddings=text)

        run(default)()  # warm-up
        fast, slow = _median_pair(run(default), run(ddim), repeats)
        rows.append({"gravity": gravity, "default": f"{default.sampler}-{default.steps}",
                     "default_s": statistics.median(fast), "ddim50_s": statistics.median(slow),
                     "ratio": statistics.median(fast) / statistics.median(slow)})
    return rows


def cold_ratio(model: Path, seconds: float, repeats: int) -> dict:
    """A cold ``simdiff generate`` against a bare torch import, each in a fresh interpreter."""
    with tempfile.TemporaryDirectory() as tmp:
        gen_cmd = [sys.executable, "-m", "simdiff", "generate", TEXT, "--length", f"{seconds:g}", "--format", "bvh",
                   "--model", str(model), "--out", tmp, "-q"]
        torch_cmd = [sys.executable, "-c", "import torch"]

        def call(cmd):
            return lambda: subprocess.run(cmd, check=True, capture_output=True)

        call(torch_cmd)()  # the files in the page cache for both
        call(gen_cmd)()
        gen_s, torch_s = _median_pair(call(gen_cmd), call(torch_cmd), repeats)
        stages = json.loads((Path(tmp) / "generation.json").read_text())["timings_s"]
    return {"generate_s": statistics.median(gen_s), "import_torch_s": statistics.median(torch_s),
            "ratio": statistics.median(gen_s) / statistics.median(torch_s), "stages_s": stages}


def viewer_seconds(model: Path, seconds: float, repeats: int) -> dict:
    """Median seconds of a warm ``POST /api/generate`` (the real server, local port)."""
    from simdiff.serve.server import ViewerServer
    from simdiff.serve.service import MotionService

    server = ViewerServer(MotionService(model), port=0)
    server.start_in_thread()
    try:
        def post(seed: int) -> None:
            body = json.dumps({"text": TEXT, "seconds": seconds, "seed": seed}).encode()
            req = urllib.request.Request(server.url + "api/generate", body, {"Content-Type": "application/json"})
            with urllib.request.urlopen(req, timeout=120) as resp:
                json.loads(resp.read())

        post(0)  # loads the model
        times = []
        for k in range(repeats):
            start = time.perf_counter()
            post(k + 1)
            times.append(time.perf_counter() - start)
    finally:
        server.shutdown()
        server.server_close()
    return {"request_s": statistics.median(times), "ratio": statistics.median(times) / VIEWER_BUDGET_S}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--model", type=Path, help="model folder (default: the shipped model)")
    parser.add_argument("--repeats", type=int, default=5, help="timed runs per side (medians)")
    parser.add_argument("--length", type=float, default=6.0, help="motion seconds (20 fps)")
    parser.add_argument("--json", help="also write the results here")
    args = parser.parse_args()
    if args.repeats < 1:
        parser.error(f"--repeats must be at least 1, got {args.repeats}")
    from simdiff.inference.default import DEFAULT_MODEL_DIR

    model = args.model or DEFAULT_MODEL_DIR
    frames = round(args.length * 20)
    print(f"machine: {platform.node()}, {os.cpu_count()} CPUs, Python {platform.python_version()}; model {model}; "
          f"{args.repeats} runs per side, medians")
    result = {"model": str(model), "repeats": args.repeats, "length_s": args.length}
    result["sampling"] = sampling_ratio(model, frames, args.repeats)
    for r in result["sampling"]:
        print(f"sampling at g {r['gravity']:g}: {r['default']} {r['default_s']:.2f} s, DDIM-50 {r['ddim50_s']:.2f} s "
              f"→ ×{r['ratio']:.2f} (target ≤ {TARGETS['sampling']})")
    cold = result["cold_generate"] = cold_ratio(model, args.length, args.repeats)
    print(f"cold generate: {cold['generate_s']:.2f} s, import torch {cold['import_torch_s']:.2f} s → ×{cold['ratio']:.2f} "
          f"(target ≤ {TARGETS['cold_generate']}); stages {cold['stages_s']}")
    view = result["warm_viewer"] = viewer_seconds(model, args.length, args.repeats)
    print(f"warm viewer request: {view['request_s']:.2f} s → ×{view['ratio']:.2f} of {VIEWER_BUDGET_S} s "
          f"(target ≤ {TARGETS['warm_viewer']})")
    if args.json:
        Path(args.json).write_text(json.dumps(result, indent=2) + "\n")


if __name__ == "__main__":
    main()
