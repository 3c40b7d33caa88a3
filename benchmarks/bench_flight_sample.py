"""Keep rate of augmented pairs with flight, per gravity group (issue 13, landing after low-g flights).

Usage:
    nice -n 10 python benchmarks/bench_flight_sample.py --sample SAMPLE.json --corpus CORPUS \\
        --out /work/scratch/me/flight_sample.jsonl
    python benchmarks/bench_flight_sample.py --summary /work/scratch/me/flight_sample.jsonl

``SAMPLE.json`` is a list of pairs ``{"clip", "env": [g_z, w_x, w_y], "group", "kept_before", ...}``
(a fixed sample drawn from an augmentation run); ``CORPUS`` holds ``new_joints/<clip>.npy``
(T, 22, 3) and the ``Mean.npy``/``Std.npy`` normaliser. Each pair is projected with the flight
clock (:func:`simdiff.sim.project.project`, ``flight=FlightConfig()``) and kept when it did not
fall, its pose d_L2 is at most ``--pose-bound`` and its mean residual force is at most
``--residual-n`` × max(1, |g_z|/9.81) N (the augmentation filter's defaults). The summary gives,
per group, the keep rate before (as recorded in the sample) and now, falls, the median pose
d_L2 and residual, and the CPU seconds. Resumable: pairs already in ``--out`` are skipped.
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
from jsonl_runs import done_keys, write_summary  # noqa: E402

POSE_BOUND = 6.557
"""Pose d_L2 bound of the augmentation filter (auto bound of the complete run)."""
RESIDUAL_N = 70.6
"""Mean residual force budget (N) at |g_z| ≤ 9.81; scaled by |g_z|/9.81 above."""


def kept(status: str, pose: float, residual_n: float, g: float, pose_bound: float = POSE_BOUND,
         residual_n_budget: float = RESIDUAL_N) -> bool:
    """The filter: no fall, pose d_L2 ≤ bound, mean residual (N) ≤ budget × max(1, |g|/9.81)."""
    return bool(status == "ok" and pose <= pose_bound and residual_n <= residual_n_budget * max(1.0, abs(g) / 9.81))


def _key(rec: dict) -> tuple:
    return rec["clip"], tuple(float(x) for x in rec["env"])


def run_pair(pair: dict, corpus: Path, model, normalizer, pose_bound: float, residual_n: float) -> dict:
    """Project one sample pair; the sample's fields plus status, pose, residual_n, kept, cpu_s."""
    from simdiff.sim.env import Environment
    from simdiff.sim.flight import FlightConfig
    from simdiff.sim.project import project

    g, wx, wy = (float(x) for x in pair["env"])
    joints = np.load(corpus / "new_joints" / f"{pair['clip']}.npy")
    t0 = time.process_time()
    _, info = project(joints, Environment(gravity=g, wind_x=wx, wind_y=wy), model=model, normalizer=normalizer,
                      flight=FlightConfig())
    res_n = float(info.residual["force_mean_n"])
    return dict(pair, status=info.status, pose=float(info.d_l2_pose), residual_n=res_n,
                kept=kept(info.status, info.d_l2_pose, res_n, g, pose_bound, residual_n),
                fall_frame=info.fall_frame, n_frames=info.n_frames, n_out=info.n_out, time_warp=info.time_warp,
                cpu_s=time.process_time() - t0)


def summary(path: Path) -> dict:
    """Per group: pairs, kept before → now, falls before → now, medians, CPU seconds."""
    recs = [json.loads(x) for x in path.read_text().splitlines() if x.strip()]
    out: dict = {"records": len(recs)}
    for group in sorted({r["group"] for r in recs}):
        rs = [r for r in recs if r["group"] == group]
        out[group] = {
            "pairs": len(rs),
            "kept_before": int(sum(bool(r["kept_before"]) for r in rs)),
            "kept": int(sum(bool(r["kept"]) for r in rs)),
            "falls_before": int(sum(r.get("status_before", "ok") != "ok" for r in rs)),
            "falls": int(sum(r["status"] != "ok" for r in rs)),
            "pose_median": float(np.nanmedian([r["pose"] for r in rs])),
            "residual_n_median": float(np.median([r["residual_n"] for r in rs])),
            "cpu_s": float(sum(r["cpu_s"] for r in rs)),
            "changed": sorted(f"{r['clip']}@{r['env'][0]:.2f}: {r['kept_before']}->{r['kept']}"
                              for r in rs if bool(r["kept_before"]) != bool(r["kept"])),
        }
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--sample", type=Path)
    ap.add_argument("--corpus", type=Path)
    ap.add_argument("--out", type=Path)
    ap.add_argument("--groups", nargs="*", help="only these groups (default all)")
    ap.add_argument("--pose-bound", type=float, default=POSE_BOUND)
    ap.add_argument("--residual-n", type=float, default=RESIDUAL_N)
    ap.add_argument("--summary", type=Path, help="print the summary of a finished --out and exit")
    args = ap.parse_args(argv)
    if args.summary:
        return write_summary(args.summary, summary)
    if args.sample is None or args.corpus is None or args.out is None:
        ap.error("--sample, --corpus and --out are needed (or --summary)")
    from simdiff.errors import SimdiffError

    os.environ.setdefault("OMP_NUM_THREADS", "1")
    try:
        pairs = json.loads(args.sample.read_text())
    except (OSError, ValueError) as e:
        raise SimdiffError(f"cannot read the sample {args.sample}: {e}") from None
    from simdiff.motion.normalize import Normalizer
    from simdiff.sim.humanoid import load_model

    normalizer = Normalizer(np.load(args.corpus / "Mean.npy"), np.load(args.corpus / "Std.npy"))
    model = load_model()
    done = done_keys(args.out, _key)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    with args.out.open("a") as f:
        for pair in pairs:
            if _key(pair) in done or (args.groups and pair["group"] not in args.groups):
                continue
            rec = run_pair(pair, args.corpus, model, normalizer, args.pose_bound, args.residual_n)
            f.write(json.dumps(rec) + "\n")
            f.flush()
            print(rec["group"], rec["clip"], rec["env"][0], rec["status"], "kept", rec["kept_before"], "->",
                  rec["kept"], f"pose {rec['pose']:.2f} residual {rec['residual_n']:.1f} N", flush=True)
    return write_summary(args.out, summary)


if __name__ == "__main__":
    raise SystemExit(main())
