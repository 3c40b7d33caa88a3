"""What ``simdiff generate --simulate`` adds: wall/CPU seconds of the simulated finish and its sliding.

Usage::

    python benchmarks/bench_simulate.py [--model DIR] [--prompts P ...] [--gravities -9.81 -3.7]
        [--length 6] [--seed 0] [--threads 1] [--repeats 1] [--compare-in-process] [--json out.json]

Each (prompt, g) runs the real command, ``simdiff generate P --gravity G --length L --format npy
--no-video --seed S``, in a fresh interpreter twice, without and with ``--simulate`` (in that order,
back to back; ``--repeats R`` pairs, medians compared), and times both from outside: what
``--simulate`` **adds** is the difference (wall and CPU seconds of the child). The simulator loads
in a worker process started before the model (:mod:`simdiff.product.finisher`; on a thread on a
one-CPU machine; ``--compare-in-process`` also times that, with ``SIMDIFF_FINISH_WORKERS=0``), so the ``simulate`` stage of ``generation.json`` alone would misstate the cost
(and the CPU the worker adds); it is reported beside it. From
``sample0_tracking.json``: tracked or fell, whether a second try was made (``attempts``) and kept
(``fallback``; :mod:`simdiff.sim.fallback`), and the sliding of the generated and the simulated
motion (mm/frame; CLoSD's definition, which counts only feet within 5 mm of y = 0, and on the
generated motion's own floor, :func:`simdiff.motion.metrics.own_floor_metrics`, which a hovering
sample cannot dodge). Targets (issue 15): ``--simulate`` adds ≤ 2 s per 6-s motion on 2 cores and
its output slides ≤ 0.5 mm/frame. On a shared machine the wall time grows with the other jobs'
load; the CPU time much less.
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

from simdiff.product.finisher import WORKERS_ENV

PROMPTS = ["a person jumps forward", "a person jumps up in place", "a person walks forward", "a person runs in a circle"]
"""The test prompts of the simulated finish (issue 15; the README's and the tutorial's examples)."""
TARGET_S = 2.0
TARGET_SLIDING = 0.5


def timed(cmd: list[str], env: dict[str, str] | None = None) -> tuple[float, float]:
    """(wall s, CPU s of the child and its worker) of one command; exits with its stderr when it fails."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    proc = subprocess.run(cmd, capture_output=True, text=True, env=None if env is None else {**os.environ, **env})
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if proc.returncode != 0:
        raise SystemExit(f"bench_simulate: {' '.join(cmd)} failed ({proc.returncode}):\n{proc.stderr.strip()}")
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def run_one(prompt: str, gravity: float, args: argparse.Namespace, out: Path) -> dict:
    """``simdiff generate`` without and with ``--simulate``: what the finish adds, its stage and tracking result."""
    import numpy as np

    from simdiff.motion.metrics import own_floor_metrics

    base = [sys.executable, "-m", "simdiff", "generate", prompt, f"--gravity={gravity:g}", "--length", f"{args.length:g}",
            "--format", "npy", "--no-video", "--seed", str(args.seed), "-q"]
    base += ["--model", args.model] if args.model else []
    base += ["--threads", str(args.threads)] if args.threads else []
    runs = []
    for _ in range(args.repeats):  # back to back, so slow phases of a shared machine hit all alike
        run = timed(base + ["--out", str(out / "plain")]) + timed(base + ["--out", str(out / "sim"), "--simulate"])
        if args.compare_in_process:
            run += timed(base + ["--out", str(out / "here"), "--simulate"], {WORKERS_ENV: "0"})
        runs.append(run)
    plain_wall, plain_cpu, sim_wall, sim_cpu = (statistics.median(r[i] for r in runs) for i in range(4))
    here = {}
    if args.compare_in_process:
        here_wall, here_cpu = (statistics.median(r[i] for r in runs) for i in (4, 5))
        here = {"added_wall_s_in_process": here_wall - plain_wall, "added_cpu_s_in_process": here_cpu - plain_cpu,
                "runs_in_process_s": [[r[4], r[5]] for r in runs]}
    meta = json.loads((out / "sim" / "generation.json").read_text())
    track = json.loads((out / "sim" / "sample0_tracking.json").read_text())
    sim = track.get("physics_simulated") or {}
    gen = track.get("physics_generated") or {}
    own = {k: own_floor_metrics(np.load(out / "sim" / f"sample0_{k}joints.npy"))["sliding_own_floor"]
           for k in ("", "simulated_")}
    return {"prompt": prompt, "gravity": gravity, "status": track["status"], "frames_out": track.get("n_out"),
            "fall_frame": track.get("fall_frame"), "attempts": track.get("attempts", 1),
            "fallback": bool(track.get("fallback", False)),
            "added_wall_s": sim_wall - plain_wall, "added_cpu_s": sim_cpu - plain_cpu,
            "plain_wall_s": plain_wall, "simulate_stage_wall_s": meta["timings_s"]["simulate"],
            "simulate_stage_cpu_s": meta["cpu_s"]["simulate"], "sample_wall_s": meta["timings_s"]["sample"],
            "sliding_generated": gen.get("sliding"), "sliding_simulated": sim.get("sliding"),
            "sliding_own_floor_generated": own[""], "sliding_own_floor_simulated": own["simulated_"],
            "anchor_version": track.get("anchor_version"), "repeats": args.repeats,
            "runs_wall_s": [[r[0], r[2]] for r in runs], "runs_cpu_s": [[r[1], r[3]] for r in runs], **here}


def here_note(row: dict) -> str:
    """``; in process +X s`` when the in-process finish was timed too."""
    return f"; in process {row['added_wall_s_in_process']:+.2f} s" if "added_wall_s_in_process" in row else ""


def summarize(rows: list[dict]) -> dict:
    """Worst and median figures over the runs, and how many meet each target."""
    added = sorted(r["added_wall_s"] for r in rows)
    slides = [r["sliding_simulated"] for r in rows if r["sliding_simulated"] is not None]
    return {"n": len(rows), "added_wall_s_median": added[len(added) // 2], "added_wall_s_max": added[-1],
            "added_cpu_s_max": max(r["added_cpu_s"] for r in rows),
            f"added_within_{TARGET_S:g}_s": sum(a <= TARGET_S for a in added),
            f"sliding_within_{TARGET_SLIDING:g}": sum(s <= TARGET_SLIDING for s in slides),
            "sliding_simulated_max": max(slides) if slides else None,
            "tracked": sum(r["status"] == "ok" for r in rows),
            "second_tries": sum(r.get("attempts", 1) > 1 for r in rows), "fallback_kept": sum(bool(r.get("fallback")) for r in rows),
            **({"added_wall_s_in_process_median": statistics.median(r["added_wall_s_in_process"] for r in rows),
                f"added_within_{TARGET_S:g}_s_in_process": sum(r["added_wall_s_in_process"] <= TARGET_S for r in rows)}
               if rows and "added_wall_s_in_process" in rows[0] else {})}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--model", default=None, help="model folder (default: the shipped default model)")
    ap.add_argument("--prompts", nargs="+", default=PROMPTS)
    ap.add_argument("--gravities", nargs="+", type=float, default=[-9.81, -3.7])
    ap.add_argument("--length", type=float, default=6.0, help="seconds per motion")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--threads", type=int, default=1, help="torch threads of each command (0: simdiff's default)")
    ap.add_argument("--repeats", type=int, default=1,
                    help="pairs of commands per (prompt, g); the medians are compared (default 1)")
    ap.add_argument("--compare-in-process", action="store_true",
                    help=f"also time --simulate with {WORKERS_ENV}=0 (the finish in the command's own process)")
    ap.add_argument("--json", type=Path, default=None, help="write the rows and the summary here")
    args = ap.parse_args(argv)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for i, prompt in enumerate(args.prompts):
            for j, g in enumerate(args.gravities):
                r = run_one(prompt, g, args, Path(tmp) / f"{i}_{j}")
                rows.append(r)
                slide = "—" if r["sliding_simulated"] is None else f"{r['sliding_simulated']:.2f}"
                print(f"{prompt!r:30} g={g:6.2f}  {r['status']:4} {r['frames_out']:4} frames  adds {r['added_wall_s']:.2f} s "
                      f"wall / {r['added_cpu_s']:.2f} s CPU{here_note(r)} (stage {r['simulate_stage_wall_s']:.2f} s; without: "
                      f"{r['plain_wall_s']:.2f} s)  sliding {slide} (own floor {r['sliding_own_floor_generated']:.2f} → "
                      f"{r['sliding_own_floor_simulated']:.2f}) mm/frame"
                      f"{'' if r['attempts'] == 1 else '  (second try' + (' kept)' if r['fallback'] else ' not kept)')}",
                      flush=True)
    summary = summarize(rows)
    print(json.dumps(summary, indent=1))
    if args.json:
        load = os.getloadavg() if hasattr(os, "getloadavg") else None
        args.json.write_text(json.dumps({"rows": rows, "summary": summary, "seed": args.seed, "length_s": args.length,
                                         "threads": args.threads, "machine": platform.platform(), "cpus": os.cpu_count(),
                                         "load_average_at_end": load}, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
