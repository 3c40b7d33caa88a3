"""CMU success-rate / residual / d_L2 sweep of the projection (resumable, one process).

Usage:
    nice -n 10 python benchmarks/bench_sim_cmu.py --clips 30 --max-frames 196 \
        --residual 0.5 0 --out reports/sim/cmu_earth.jsonl
    nice -n 10 python benchmarks/bench_sim_cmu.py --clips all --workers 2 --out all.jsonl

Clips: the 7 probe clips first (16_15 walk, 16_17 turn, 16_36 / 16_45 runs, 16_05 / 16_06
jumps, 13_30 jacks), then the other AMC trials of ../shared/data/cmu in sorted order,
cropped to their first ``--max-frames`` frames at 20 fps.
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
CMU = Path(os.environ.get("SIMDIFF_SHARED_DATA", ROOT.parent / "shared" / "data")) / "cmu"
PROBE_CLIPS = ["16_15", "16_17", "16_36", "16_45", "16_05", "16_06", "13_30"]


def cmu_fps() -> dict[str, float]:
    out = {}
    with open(CMU / "CMU_data.csv") as f:
        for row in csv.DictReader(f):
            try:
                out[f"{int(row['Subject']):02d}_{int(row['Trial #']):02d}"] = float(row["framerate"])
            except (ValueError, KeyError):
                pass
    return out


def load_clip(name: str, fps_table: dict[str, float], max_frames: int) -> np.ndarray:
    from simdiff.motion.io.asf_amc import find_asf, read_amc
    from simdiff.motion.io.retarget import retarget_rig as retarget

    path = CMU / "amc" / f"{name}.amc"
    rig = read_amc(path, find_asf(path), fps=fps_table.get(name, 120.0))
    joints = np.asarray(retarget(rig, canonical=True), dtype=np.float64)
    return joints[:max_frames]


def clip_list(n: int | None) -> list[str]:
    """The probe clips, then the other usable AMC trials sorted (subject 35 has no ASF); None: all."""
    usable = sorted(p.stem for p in (CMU / "amc").glob("*.amc") if not p.stem.startswith("35_"))
    rest = [c for c in usable if c not in PROBE_CLIPS]
    return (PROBE_CLIPS + rest)[:n]


def run_clip(task: tuple) -> list[dict]:
    """Project one clip under every residual bound; one record per bound (or an error record)."""
    clip, todo, max_frames, gravity, fps = task
    from simdiff.motion.normalize import Normalizer
    from simdiff.sim.env import Environment
    from simdiff.sim.project import project
    from simdiff.sim.residual import ResidualConfig

    try:
        joints = load_clip(clip, fps, max_frames)
    except Exception as exc:  # unreadable trial: record and go on
        return [{"clip": clip, "residual_bound": R, "status": "unreadable", "error": str(exc)} for R in todo]
    norm = Normalizer.from_dir(CMU.parent / "humanml3d")
    out = []
    for R in todo:
        _, info = project(joints, Environment(gravity), residual=ResidualConfig(max_force=R), normalizer=norm)
        rec = info.to_dict()
        rec.update(clip=clip, residual_bound=R)
        rec["d_l2"] = None if not np.isfinite(rec["d_l2"]) else rec["d_l2"]
        out.append(rec)
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--clips", default="30", help="how many clips (probe clips first), or 'all'")
    ap.add_argument("--workers", type=int, default=1, help="processes, one clip each")
    ap.add_argument("--max-frames", type=int, default=196)
    ap.add_argument("--residual", type=float, nargs="+", default=[0.5, 0.0])
    ap.add_argument("--gravity", type=float, default=-9.81)
    ap.add_argument("--out", type=Path, default=ROOT / "reports" / "sim" / "cmu_earth.jsonl")
    args = ap.parse_args(argv)

    done = set()
    if args.out.exists():
        for line in args.out.read_text().splitlines():
            r = json.loads(line)
            done.add((r["clip"], r["residual_bound"]))
    args.out.parent.mkdir(parents=True, exist_ok=True)
    fps = cmu_fps()
    n = None if args.clips == "all" else int(args.clips)
    tasks = []
    for clip in clip_list(n):
        todo = [R for R in args.residual if (clip, R) not in done]
        if todo:
            tasks.append((clip, todo, args.max_frames, args.gravity, fps))
    if args.workers > 1:
        import multiprocessing as mp
        from concurrent.futures import ProcessPoolExecutor

        from simdiff.sim.pool import limit_threads

        ex = ProcessPoolExecutor(max_workers=args.workers, mp_context=mp.get_context("spawn"),
                                 initializer=limit_threads, initargs=(1,))
        results = ex.map(run_clip, tasks, chunksize=1)
    else:
        ex, results = None, map(run_clip, tasks)
    for recs in results:
        for rec in recs:
            with open(args.out, "a") as f:  # one line per record: a crash loses at most the clip in flight
                f.write(json.dumps(rec) + "\n")
            if rec["status"] == "unreadable":
                print(f"{rec['clip']}: unreadable ({rec['error']})", file=sys.stderr)
                continue
            print(f"{rec['clip']} R={rec['residual_bound']}: {rec['status']} fall={rec['fall_frame']} "
                  f"d_L2={rec['d_l2'] or float('nan'):.2f} err={rec['err_mm']:.0f}mm "
                  f"F={rec['residual']['force_mean_mg']:.3f}mg cpu={rec['cpu_s']:.1f}s dur={rec['duration_s']:.1f}s",
                  flush=True)
    if ex is not None:
        ex.shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
