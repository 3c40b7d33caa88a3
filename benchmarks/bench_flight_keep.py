"""Keep rate of clips with flight under weak gravity, with and without the re-timed second try (issue 13).

Usage:
    nice -n 10 python benchmarks/bench_flight_keep.py --corpus CORPUS --out /work/scratch/me/flight_keep.jsonl \\
        --clips 100 --workers 2
    python benchmarks/bench_flight_keep.py --summary /work/scratch/me/flight_keep.jsonl

Draws ``--clips`` originals of the ``--split`` (mirrors ``M…`` and the manifest's acrobatics left out)
whose source has flight (longest flight ≥ 0.2 s, :func:`simdiff.motion.flight.has_flight`: the
augmentation report's *flight* class), seeded. Each clip is projected at Earth once and, for every
gravity bin of ``--bins``, at one g drawn uniformly in that bin (the same g for both variants):
``none`` = one try (the augmentation before :mod:`simdiff.sim.retime`), ``retime`` = the default
:class:`simdiff.sim.retime.RetimeConfig` (a second try on the Froude-slowed source when the first fell
or strayed). Every pair uses the augmentation's settings (flight clock, residual bound 0.5, the
corpus's Mean/Std) and is judged by its filter: no fall, pose d_L2 ≤ ``--pose-bound`` (default the
complete corpus3 run's calibrated 6.557), mean residual ≤ 70.6 N × max(1, |g|/9.81).

The summary gives, per bin and variant: pairs, finished, kept with a Wilson 95 % interval, how often
the re-timed rollout was the one kept, median pose d_L2, median time warp, the median longest flight
÷ the clip's own Earth rollout's (clips with an Earth flight), and CPU seconds. Resumable: records
already in ``--out`` are skipped.
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

POSE_BOUND = 6.557
RESIDUAL_N = 70.6
DEFAULT_BINS = ("-3:-1", "-5:-3", "-8.5:-5")


def parse_bin(text: str) -> tuple[float, float]:
    """``"lo:hi"`` (m/s², lo < hi ≤ −1) → (lo, hi)."""
    try:
        lo, hi = (float(x) for x in text.split(":"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a gravity bin 'lo:hi', got {text!r}") from None
    if not lo < hi <= -1.0:
        raise argparse.ArgumentTypeError(f"expected lo < hi <= -1 in a gravity bin, got {text!r}")
    return lo, hi


def pick_clips(corpus: Path, split: str, n: int, seed: int) -> list[tuple[str, float]]:
    """``n`` seeded (clip, source longest flight s) of the split's originals with flight, no acrobatics."""
    from simdiff.data.augment.classes import load_motion_types
    from simdiff.motion.flight import flight_stats, has_flight

    split_file = corpus / f"{split}.txt"
    if not split_file.is_file():
        raise SystemExit(f"split file not found: {split_file}")
    ids = [x.strip() for x in split_file.read_text().splitlines() if x.strip() and not x.startswith("M")]
    types = load_motion_types(corpus) or {}
    rng = np.random.default_rng(seed)
    out: list[tuple[str, float]] = []
    for cid in rng.permutation(ids):
        if types.get(str(cid)) == "acrobatics":
            continue
        fs = flight_stats(np.load(corpus / "new_joints" / f"{cid}.npy"))
        if has_flight(fs["flight_s"]):
            out.append((str(cid), float(fs["flight_s"])))
            if len(out) == n:
                break
    return out


def tasks(clips: list[tuple[str, float]], bins: list[tuple[float, float]], seed: int) -> list[dict]:
    """One Earth task per clip, then per bin one g (seeded per clip) under both variants."""
    out = []
    for i, (cid, src_flight) in enumerate(clips):
        rng = np.random.default_rng([seed, i])
        out.append(dict(clip=cid, src_flight=src_flight, bin="earth", g=-9.81, variant="none"))
        for lo, hi in bins:
            g = float(rng.uniform(lo, hi))
            for v in ("none", "retime"):
                out.append(dict(clip=cid, src_flight=src_flight, bin=f"g[{lo:g},{hi:g})", g=g, variant=v))
    return out


def _key(rec: dict) -> tuple:
    return rec["clip"], rec["bin"], rec["variant"]


_STATE: dict = {}


def run_task(task: dict) -> dict:
    """Project one task (in a worker: single-threaded, model and normaliser loaded once)."""
    from simdiff.data.augment.filter import FilterConfig, keep_pair
    from simdiff.motion.flight import flight_stats
    from simdiff.sim.env import Environment
    from simdiff.sim.flight import FlightConfig
    from simdiff.sim.project import project
    from simdiff.sim.retime import RetimeConfig

    if not _STATE:
        from simdiff.motion.normalize import Normalizer
        from simdiff.sim.humanoid import load_model
        from simdiff.sim.pool import limit_threads

        limit_threads(1)
        corpus = Path(task["corpus"])
        _STATE.update(model=load_model(), norm=Normalizer.from_dir(corpus))
    corpus = Path(task["corpus"])
    joints = np.load(corpus / "new_joints" / f"{task['clip']}.npy")
    t0 = time.process_time()
    out, info = project(joints, Environment(gravity=task["g"]), model=_STATE["model"], normalizer=_STATE["norm"],
                        flight=FlightConfig(), retime=RetimeConfig() if task["variant"] == "retime" else None)
    fs = flight_stats(out) if len(out) >= 2 else {"flight_s": 0.0, "apex_gain_m": 0.0}
    res_n = float(info.residual["force_mean_n"])
    kept = keep_pair(info, FilterConfig(max_pose_d_l2=task["pose_bound"], max_residual_n=task["residual_n"]))[0]
    rec = {k: v for k, v in task.items() if k not in ("corpus",)}
    rec.update(status=info.status, pose=float(info.d_l2_pose), residual_n=res_n, kept=kept, n_out=info.n_out,
               time_warp=info.time_warp, retime_scale=info.retime_scale, attempts=info.attempts,
               flight_s=float(fs["flight_s"]), apex_m=float(fs["apex_gain_m"]), cpu_s=time.process_time() - t0)
    return rec


def summary(path: Path) -> dict:
    """Per bin × variant: pairs, finished, kept (Wilson 95 %), re-timed kept, medians, CPU s."""
    from simdiff.eval.model_check.detect import wilson

    recs = [json.loads(x) for x in path.read_text().splitlines() if x.strip()]
    earth_flight = {r["clip"]: r["flight_s"] for r in recs if r["bin"] == "earth" and r["status"] == "ok"}
    out: dict = {"records": len(recs), "clips": len({r["clip"] for r in recs}), "pose_bound": None}
    for b in sorted({r["bin"] for r in recs}, key=lambda s: (s != "earth", s)):
        for v in ("none", "retime"):
            rs = [r for r in recs if r["bin"] == b and r["variant"] == v]
            if not rs:
                continue
            out["pose_bound"] = rs[0]["pose_bound"]
            k = sum(r["kept"] for r in rs)
            ratios = [r["flight_s"] / earth_flight[r["clip"]] for r in rs
                      if r["status"] == "ok" and earth_flight.get(r["clip"], 0) > 0]
            out[f"{b} {v}"] = {
                "pairs": len(rs), "finished": int(sum(r["status"] == "ok" for r in rs)), "kept": int(k),
                "kept_rate": k / len(rs), "kept_wilson95": list(wilson(int(k), len(rs))[1:]),
                "kept_retimed": int(sum(r["kept"] and r["retime_scale"] > 1 for r in rs)),
                "second_tries": int(sum(r["attempts"] > 1 for r in rs)),
                "pose_median": float(np.nanmedian([r["pose"] for r in rs])),
                "time_warp_median_kept": float(np.median([r["time_warp"] for r in rs if r["kept"]])) if k else None,
                "flight_vs_earth_median_finished": float(np.median(ratios)) if ratios else None,
                "cpu_s": float(sum(r["cpu_s"] for r in rs)),
            }
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--corpus", type=Path)
    ap.add_argument("--out", type=Path)
    ap.add_argument("--split", default="train")
    ap.add_argument("--clips", type=int, default=100, help="clips with flight to draw (default 100)")
    ap.add_argument("--bins", type=parse_bin, nargs="+", default=[parse_bin(b) for b in DEFAULT_BINS],
                    help="gravity bins lo:hi (default -3:-1 -5:-3 -8.5:-5)")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--workers", type=int, default=1)
    ap.add_argument("--pose-bound", type=float, default=POSE_BOUND)
    ap.add_argument("--residual-n", type=float, default=RESIDUAL_N)
    ap.add_argument("--summary", type=Path, help="write the summary of a finished --out and exit")
    args = ap.parse_args(argv)
    if args.summary:
        return write_summary(args.summary, summary)
    if args.corpus is None or args.out is None:
        ap.error("--corpus and --out are needed (or --summary)")
    if args.clips < 1:
        ap.error(f"--clips must be >= 1, got {args.clips}")
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    clips = pick_clips(args.corpus, args.split, args.clips, args.seed)
    done = done_keys(args.out, _key)
    todo = [dict(t, corpus=str(args.corpus), pose_bound=args.pose_bound, residual_n=args.residual_n)
            for t in tasks(clips, args.bins, args.seed) if _key(t) not in done]
    print(f"{len(clips)} clips with flight, {len(todo)} tasks to run ({len(done)} done)", flush=True)
    run_appending(todo, run_task, args.out, args.workers,
                  lambda r: f"{r['clip']} {r['bin']} {r['variant']} g={r['g']:.2f} {r['status']} kept={r['kept']} "
                            f"pose={r['pose']:.2f} x{r['retime_scale']:.2f}")
    return write_summary(args.out, summary)


if __name__ == "__main__":
    raise SystemExit(main())
