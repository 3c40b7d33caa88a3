"""Wall time of the README command, ``simdiff generate TEXT --gravity -3.7 --wind 2 0``, end to end.

Usage::

    python benchmarks/bench_generate.py [--model DIR] [--preset small] [--length 6]
        [--repeats 3] [--no-video] [--env-guidance S [S ...]] [--json out.json]

Each repeat runs the real command in a fresh interpreter (``python -m simdiff generate ...``) and
times it from outside: interpreter start and imports, model load (weights + MiniLM), text
encoding, DDIM-50 sampling, decoding, writing ``.npy``/BVH and rendering the GIF. The per-stage
breakdown comes from the run's ``generation.json``; ``startup`` is what is left (interpreter,
imports, argument checks). Wall seconds and CPU seconds (user + system of the child) are both
reported: on a machine shared with other jobs the wall time grows with their load while the CPU
time does not (with one thread it is close to the wall time the command takes on an idle machine).
One extra run under ``python -X importtime`` lists the heaviest imports.

``--env-guidance 1 2`` times the command with each environment-guidance value in turn (repeat i runs
every value before repeat i + 1, so a change of load hits them alike) and reports each value's
summary and its median wall time as a ratio to the first value's, measured in one run; without it
the command uses the model's ``sampling.json``.

Without ``--model`` the shipped default model is used when installed, else a random model of
``--preset`` size (speed does not depend on the weights) with the CMU feature statistics.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

README_TEXT = "a person jumps forward"
README_ENV = ["--gravity", "-3.7", "--wind", "2", "0"]
TARGET_S = 10.0


def random_model(folder: Path, preset: str) -> Path:
    """Save a random SimDiff model of backbone ``preset`` (continuous φ) with the CMU feature statistics."""
    import numpy as np
    import torch

    from simdiff.model import ModelConfig, SimConfig, backbone_preset, build_network
    from simdiff.inference.generator import MotionGenerator

    torch.manual_seed(0)
    config = ModelConfig(backbone=backbone_preset(preset), sim=SimConfig())
    stats = Path(__file__).resolve().parents[1] / "simdiff" / "assets" / "cmu_stats"
    mean = torch.from_numpy(np.load(stats / "Mean.npy")).float()
    std = torch.from_numpy(np.load(stats / "Std.npy")).float()
    MotionGenerator(build_network(config), config, mean=mean, std=std).save(folder)
    return folder


def command(model: Path, out: Path, length: float, no_video: bool, env_guidance: float | None = None) -> list[str]:
    cmd = [sys.executable, "-m", "simdiff", "generate", README_TEXT, *README_ENV, "--model", str(model),
           "--out", str(out), "--length", f"{length:g}", "-q"]
    return (cmd + (["--format", "npy,bvh"] if no_video else [])
            + (["--env-guidance", f"{env_guidance:g}"] if env_guidance is not None else []))


def timed_run(cmd: list[str], out: Path) -> dict:
    """Run ``cmd``; returns outer wall/CPU seconds and the stage timings from ``generation.json``."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    proc = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if proc.returncode != 0:
        raise SystemExit(f"bench_generate: the command failed ({proc.returncode}):\n{proc.stderr}")
    meta = json.loads((out / "generation.json").read_text())
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    stages_wall = {k: v for k, v in meta["timings_s"].items() if k != "total"}
    stages_cpu = {k: v for k, v in meta["cpu_s"].items() if k != "total"}
    stages_wall["startup"] = round(wall - sum(stages_wall.values()), 3)
    stages_cpu["startup"] = round(cpu - sum(stages_cpu.values()), 3)
    return {"wall_s": round(wall, 3), "cpu_s": round(cpu, 3), "threads": meta.get("threads"),
            "stages_wall_s": stages_wall, "stages_cpu_s": stages_cpu,
            "files": sorted(p.name for p in out.iterdir())}


def import_profile(cmd: list[str], top: int = 10) -> dict:
    """Import wall time of the command (``-X importtime``): total and the heaviest imports made from top level
    or from inside functions (the lazy imports of the run path), in seconds."""
    proc = subprocess.run([cmd[0], "-X", "importtime", *cmd[1:]], capture_output=True, text=True)
    rows = []
    for line in proc.stderr.splitlines():
        if not line.startswith("import time:") or "|" not in line:
            continue
        parts = line[len("import time:"):].split("|")
        try:
            cumulative = int(parts[1])
        except ValueError:
            continue  # header
        name = parts[2]
        if not name.startswith("  "):  # top level (indent 1 space)
            rows.append((name.strip(), cumulative / 1e6))
    rows.sort(key=lambda r: -r[1])
    return {"total_s": round(sum(t for _, t in rows), 3),
            "heaviest_s": {name: round(t, 3) for name, t in rows[:top]}}


IMPORT_GROUPS: tuple[tuple[str, str], ...] = (
    ("cli (argparse + command discovery)", "from simdiff.cli.main import build_parser; build_parser()"),
    ("checks (simdiff.product.request)", "import simdiff.product.request"),
    ("torch", "import torch"),
    ("simdiff.model + diffusion", "import simdiff.inference.default, simdiff.inference.generator"),
    ("text encoder (MiniLM)", "import simdiff.text.minilm"),
    ("simdiff.motion.features (scipy.ndimage)", "import simdiff.motion.features"),
    ("simdiff.motion.io (BVH writer; scipy.signal, .spatial)", "import simdiff.motion.io.bvh_writer"),
    ("simdiff.viz.stick (matplotlib 3D)", "import simdiff.viz.stick"),
    ("PIL + tqdm", "import PIL.Image, tqdm.auto"),
)
"""Import groups in the order ``simdiff generate`` imports them (marginal cost of each)."""


def import_cpu() -> dict[str, float]:
    """Marginal CPU seconds of each :data:`IMPORT_GROUPS` entry in a fresh interpreter (robust to machine load)."""
    code = ["import json, time", "out = {}"]
    for name, stmt in IMPORT_GROUPS:
        code += ["t = time.process_time()", stmt, f"out[{name!r}] = round(time.process_time() - t, 3)"]
    code.append("print(json.dumps(out))")
    proc = subprocess.run([sys.executable, "-c", "\n".join(code)], capture_output=True, text=True, check=True)
    result = json.loads(proc.stdout)
    result["total"] = round(sum(result.values()), 3)
    return result


def summarise(runs: list[dict]) -> dict:
    """Median and best of each number over the repeats."""
    def stat(values: list[float]) -> dict:
        return {"median": round(statistics.median(values), 3), "best": round(min(values), 3)}

    stages = list(runs[0]["stages_wall_s"])
    return {
        "wall_s": stat([r["wall_s"] for r in runs]),
        "cpu_s": stat([r["cpu_s"] for r in runs]),
        "stages_wall_s": {k: stat([r["stages_wall_s"][k] for r in runs]) for k in stages},
        "stages_cpu_s": {k: stat([r["stages_cpu_s"][k] for r in runs]) for k in stages},
    }


def _sampler_label(model: Path) -> str:
    """What the command samples with: the model's ``sampling.json`` (simdiff generate's defaults) or the CLI's."""
    from simdiff.inference.default import sampling_config

    config = sampling_config(model)
    return (f"{config.sampler}-{config.steps}, guidance {config.guidance:g} (batched CFG), "
            f"sampling: {json.dumps(config.to_dict(), sort_keys=True)}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--model", type=Path, help="model folder (default: shipped model, else a random --preset one)")
    parser.add_argument("--preset", default="small", help="backbone size of the random model (default small)")
    parser.add_argument("--length", type=float, default=6.0, help="motion length in seconds (default 6)")
    parser.add_argument("--repeats", type=int, default=3, help="timed runs (default 3)")
    parser.add_argument("--no-video", action="store_true", help="skip the GIF (--format npy,bvh)")
    parser.add_argument("--no-importtime", action="store_true", help="skip the -X importtime run")
    parser.add_argument("--env-guidance", type=float, nargs="+", metavar="S",
                        help="time the command with each of these environment-guidance values in turn and report "
                             "the ratios to the first (default: the model's sampling.json)")
    parser.add_argument("--json", type=Path, help="also write the results here")
    args = parser.parse_args()
    if args.repeats < 1:
        raise SystemExit(f"bench_generate: --repeats must be at least 1, got {args.repeats}")
    values: list[float | None] = list(args.env_guidance) if args.env_guidance else [None]

    from simdiff.inference.default import DEFAULT_MODEL_DIR

    with tempfile.TemporaryDirectory(prefix="bench_generate_") as tmp:
        tmp_dir = Path(tmp)
        if args.model is not None:
            model, kind = args.model, "given"
        elif (DEFAULT_MODEL_DIR / "model.safetensors").is_file():
            model, kind = DEFAULT_MODEL_DIR, "shipped default"
        else:
            model, kind = random_model(tmp_dir / "model", args.preset), f"random {args.preset} SimDiff"
        config = json.loads((Path(model) / "config.json").read_text())
        load_before = os.getloadavg()
        by_value: dict[int, list[dict]] = {j: [] for j in range(len(values))}
        for i in range(args.repeats):
            for j, value in enumerate(values):
                out = tmp_dir / f"out{i}_{j}"
                run = timed_run(command(model, out, args.length, args.no_video, value), out)
                by_value[j].append(run)
                label = "" if value is None else f" (env guidance {value:g})"
                print(f"run {i}{label}: wall {run['wall_s']:.2f} s, cpu {run['cpu_s']:.2f} s", file=sys.stderr)
        runs = by_value[0]
        imports = None if args.no_importtime else import_profile(
            command(model, tmp_dir / "imp", args.length, args.no_video, values[0]))
        imports_cpu = import_cpu()
        load_after = os.getloadavg()

    summary = summarise(runs)
    result = {
        "benchmark": "bench_generate",
        "command": " ".join(["simdiff", "generate", repr(README_TEXT), *README_ENV, "--length", f"{args.length:g}"]
                            + (["--format", "npy,bvh"] if args.no_video else [])
                            + (["--env-guidance", f"{values[0]:g}"] if values[0] is not None else [])),
        "model": {"kind": kind, "path": str(model), "latent_dim": config["backbone"]["latent_dim"],
                  "num_layers": config["backbone"]["num_layers"], "simdiff": config["sim"] is not None},
        "sampler": _sampler_label(model),
        "threads_used": runs[0]["threads"],
        "machine": {"cpus": os.cpu_count(), "platform": platform.platform(), "python": platform.python_version(),
                    "loadavg_1min_before_after": [round(load_before[0], 2), round(load_after[0], 2)]},
        "target_s": TARGET_S,
        "summary": summary,
        "imports_wall_s": imports,
        "imports_cpu_s": imports_cpu,
        "runs": runs,
    }
    if len(values) > 1:
        first = summary["wall_s"]["median"]
        result["env_guidance"] = [
            {"value": value, "summary": summarise(by_value[j]), "runs": by_value[j],
             "wall_ratio_to_first": round(statistics.median(r["wall_s"] for r in by_value[j]) / first, 3)}
            for j, value in enumerate(values)]
    text = json.dumps(result, indent=2)
    print(text)
    if args.json:
        args.json.write_text(text + "\n")


if __name__ == "__main__":
    main()
