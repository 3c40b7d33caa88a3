"""Paired augmentation on a small mixed CMU sample (issue 13, items 1, 3, 4), without a corpus.

Usage:
    nice -n 10 python benchmarks/bench_augment_sample.py --workers 2 --out reports/augment/sample.jsonl
    python benchmarks/bench_augment_sample.py --summary reports/augment/sample.jsonl

Every clip is projected at Earth and under its K paired conditions
(:func:`simdiff.data.augment.conditions.paired_conditions`, seed 0) with the flight clock, and
once at Earth without it (the previous pipeline, for the filter calibration). d_L2 uses the
official HumanML3D Mean/Std (``humanml3d/`` in the shared data). The summary calibrates the
pose-d_L2 threshold on the Earth pairs (same keep rate as the previous filter: tracked,
d_L2 ≤ 7, residual ≤ 0.1·m·g, without the clock), then gives keep rates and rejections per
condition bin, the confound check and the physics-signal table. Resumable.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from jsonl_runs import done_keys, run_appending, write_summary  # noqa: E402


def sample_clips(n: int) -> list[str]:
    """``n`` usable CMU AMC trials spread evenly over the sorted list (subject 35 has no ASF)."""
    from bench_sim_cmu import CMU

    usable = sorted(p.stem for p in (CMU / "amc").glob("*.amc") if not p.stem.startswith("35_"))
    idx = np.linspace(0, len(usable) - 1, n).round().astype(int)
    return [usable[i] for i in idx]


def run_task(task: tuple) -> dict:
    clip, cond, clock, max_frames = task
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    from bench_sim_cmu import CMU, cmu_fps, load_clip

    from simdiff.data.augment.signal import measure
    from simdiff.motion.normalize import Normalizer
    from simdiff.sim.env import Environment
    from simdiff.sim.flight import FlightConfig
    from simdiff.sim.project import project

    t0 = time.perf_counter()
    joints = load_clip(clip, cmu_fps(), max_frames)
    norm = Normalizer.from_dir(CMU.parent / "humanml3d")
    rec = {"clip": clip, "index": cond["index"], "factor": cond["factor"], "env": cond["env"], "clock": clock,
           "content": measure(joints)}
    try:
        out, info = project(joints, Environment(*cond["env"]), normalizer=norm,
                            flight=FlightConfig() if clock else None)
        rec["info"] = info.to_dict()
        rec["signal"] = measure(out) if info.success else None
        rec["sim_s"] = (len(out) - 1) / 20.0
    except Exception as exc:  # noqa: BLE001 - one record per pair
        rec["info"] = f"{type(exc).__name__}: {exc}"
    rec["wall_s"] = time.perf_counter() - t0
    return rec


def summary(path: Path) -> dict:
    from simdiff.data.augment.confound import confound_check
    from simdiff.data.augment.filter import CRITERIA, FilterConfig, keep_pair, rejections
    from simdiff.data.augment.signal import condition_bin, signal_table

    recs = [json.loads(x) for x in path.read_text().splitlines() if x.strip()]
    old = [r for r in recs if not r["clock"]]
    new = [r for r in recs if r["clock"]]
    paper = FilterConfig(max_pose_d_l2=None, max_residual_n=None, max_d_l2=7.0, max_residual=0.1)
    old_kept = sum(keep_pair(r["info"], paper)[0] for r in old)
    # calibration: the smallest pose threshold that keeps as many Earth pairs as the old filter
    earth = [r for r in new if r["index"] == 0 and isinstance(r["info"], dict)]
    ok = [r for r in earth if not rejections(r["info"], FilterConfig(max_pose_d_l2=None))["failed"]
          and not rejections(r["info"], FilterConfig(max_pose_d_l2=None))["residual"]]
    pose = sorted(r["info"]["d_l2_pose"] for r in ok if np.isfinite(r["info"]["d_l2_pose"]))
    thr = pose[min(old_kept, len(pose)) - 1] if pose and old_kept else None
    cfg = FilterConfig(max_pose_d_l2=FilterConfig().max_pose_d_l2)
    out: dict = {"clips": len({r["clip"] for r in recs}), "pairs": len(new),
                 "earth_old_filter": {"pairs": len(old), "kept": old_kept},
                 "pose_threshold_same_earth_rate": thr, "filter": vars(cfg)}
    bins: dict[str, dict] = {}
    table_in = []
    for r in new:
        kept, reason = keep_pair(r["info"], cfg)
        b = condition_bin(r["env"])
        row = bins.setdefault(b, {"pairs": 0, "kept": 0, **{c: 0 for c in CRITERIA}, "error": 0})
        row["pairs"] += 1
        row["kept"] += kept
        if isinstance(r["info"], str):
            row["error"] += 1
        else:
            for c, v in rejections(r["info"], cfg).items():
                row[c] += v
        table_in.append({"clip": r["clip"], "env": r["env"], "kept": kept, "signal": r.get("signal")})
    for row in bins.values():
        row["keep_rate"] = row["kept"] / row["pairs"]
    out["per_bin"] = dict(sorted(bins.items()))
    flight_clips = {r["clip"] for r in new if r["index"] == 0 and r["content"]["flight_s"] >= 0.1}
    for name, sel in (("with_flight", lambda c: c in flight_clips), ("without_flight", lambda c: c not in flight_clips)):
        sub: dict[str, list[int]] = {}
        for t in table_in:
            if sel(t["clip"]):
                sub.setdefault(condition_bin(t["env"]), []).append(int(t["kept"]))
        out[f"keep_rate_{name}"] = {b: {"pairs": len(v), "keep_rate": float(np.mean(v))} for b, v in sorted(sub.items())}
    kept_pairs = [t for t in table_in if t["kept"]]
    content = {r["clip"]: r["content"] for r in new}
    out["confound"] = confound_check(kept_pairs, content)
    out["signal"] = signal_table(table_in)
    info = [r for r in new if isinstance(r["info"], dict)]
    out["cpu_s_per_sim_s"] = float(sum(r["info"]["cpu_s"] for r in info) / max(sum(r.get("sim_s", 0) for r in info), 1e-9))
    out["cpu_s_total"] = float(sum(r["info"]["cpu_s"] for r in info))
    out["time_warp_median_by_bin"] = {}
    for b in out["per_bin"]:
        w = [r["info"]["time_warp"] for r in info if condition_bin(r["env"]) == b]
        out["time_warp_median_by_bin"][b] = float(np.median(w)) if w else None
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", type=Path, default=Path("reports/augment/sample.jsonl"))
    ap.add_argument("--clips", type=int, default=24, help="clips spread over the CMU list")
    ap.add_argument("--k", type=int, default=6)
    ap.add_argument("--max-frames", type=int, default=196)
    ap.add_argument("--workers", type=int, default=1)
    ap.add_argument("--summary", type=Path)
    args = ap.parse_args(argv)
    if args.summary:
        return write_summary(args.summary, summary)
    from simdiff.data.augment.conditions import paired_conditions

    done = done_keys(args.out, lambda r: (r["clip"], r["index"], r["clock"]))
    tasks = []
    for clip in sample_clips(args.clips):
        conds = [c.to_dict() for c in paired_conditions(clip, args.k, seed=0)]
        tasks += [(clip, c, True, args.max_frames) for c in conds] + [(clip, conds[0], False, args.max_frames)]
    tasks = [t for t in tasks if (t[0], t[1]["index"], t[2]) not in done]
    t0 = time.perf_counter()
    run_appending(tasks, run_task, args.out, args.workers, lambda rec: " ".join(str(v) for v in (
        rec["clip"], rec["env"], rec["clock"], rec["info"]["status"] if isinstance(rec["info"], dict) else rec["info"])))
    print("wall_s", time.perf_counter() - t0)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
