"""Tracking under high gravity with Earth-strength vs gravity-scaled actuators (issue 13).

Usage:
    nice -n 10 python benchmarks/bench_high_gravity.py --corpus /work/scratch/c12b/corpus3 \\
        --shards /work/scratch/aug/paired_k6_shared/shards --log /work/scratch/g13/high_gravity.jsonl \\
        --out reports/augment/high_gravity.json

Clips: train clips of the corpus whose Earth pair tracked in an augmentation run (``--shards``),
without flight (``content.flight_s`` < 0.2 s) and not acrobatics, stratified by source/type
(Bandai walks, Bandai gestures, CMU AMC, acLSTM), evenly spaced in sorted order. Each clip is
projected as the augmentation does (:func:`simdiff.sim.project.project` with the flight clock,
residual bound 0.5, the corpus Mean/Std) at g = −9.81 (one run: every variant is the same
there) and at each high gravity under each strength variant (:mod:`simdiff.sim.strength`):

* ``earth``: Earth-strength actuators (before issue 13);
* ``gains_limits``: kp, kd and force limits × max(1, |g|/9.81);
* ``limits``: force limits only × that factor;
* ``balance``: only the tracker's balance layer scaled (:func:`simdiff.sim.strength.scale_balance`);
* ``actuators_balance``: kp, kd, force limits and the balance layer;
* ``all``: those and the root residual's torque bound (the default :class:`StrengthConfig`).

The log is resumable (one JSON line per projection); the summary (success rate, medians over
the tracked rollouts of pose d_L2, residual N, local joint error mm, per g and variant, and
over the clips tracked by every variant) goes to ``--out``. One thread.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from collections import defaultdict
from pathlib import Path

import numpy as np

STRATA: dict[str, tuple[str, tuple[str, ...]]] = {
    "bandai_walk": ("bandai", ("walk",)),
    "bandai_gesture": ("bandai", ("gesture",)),
    "cmu_amc": ("cmu-amc", ("walk", "exercise", "dance", "other", "sports")),
    "aclstm": ("cmu-aclstm", ("dance", "sports")),
}
VARIANTS = ("earth", "gains_limits", "limits", "balance", "actuators_balance", "v2", "all")


def strength_of(variant: str):
    from simdiff.sim.strength import NO_SCALING, StrengthConfig

    return {"earth": NO_SCALING, "gains_limits": StrengthConfig(balance=False, residual_torque=False, residual_gains=False),
            "limits": StrengthConfig(gains=False, balance=False, residual_torque=False, residual_gains=False),
            "balance": StrengthConfig(gains=False, limits=False, residual_torque=False, residual_gains=False),
            "actuators_balance": StrengthConfig(residual_torque=False, residual_gains=False),
            "v2": StrengthConfig(residual_gains=False), "all": StrengthConfig()}[variant]


def pick_clips(corpus: Path, shards: Path, per_stratum: int) -> dict[str, list[str]]:
    """``per_stratum`` clips per stratum that tracked at Earth without flight, evenly spaced."""
    manifest = {c["id"]: c for c in json.loads((corpus / "manifest.json").read_text())["clips"]}
    train = set((corpus / "train.txt").read_text().split())
    ok: set[str] = set()
    for path in sorted(shards.glob("shard_*.json")):
        for r in json.loads(path.read_text())["records"]:
            info = r.get("info")
            if (r.get("factor") == "earth" and not r.get("mirrored_from") and isinstance(info, dict)
                    and info.get("success") and ((r.get("content") or {}).get("flight_s") or 0.0) < 0.2):
                ok.add(r["clip"])
    out = {}
    for name, (source, types) in STRATA.items():
        cands = sorted(c for c in ok if c in train and c in manifest and manifest[c]["source"] == source
                       and manifest[c]["motion_type"] in types)
        idx = np.linspace(0, len(cands) - 1, min(per_stratum, len(cands))).round().astype(int)
        out[name] = [cands[i] for i in idx]
    return out


def run_one(corpus: Path, clip: str, g: float, variant: str) -> dict:
    from simdiff.data.augment.run import load_source_joints
    from simdiff.sim.env import Environment
    from simdiff.sim.flight import FlightConfig
    from simdiff.sim.pool import _normalizer
    from simdiff.sim.project import project
    from simdiff.sim.residual import ResidualConfig

    joints = load_source_joints(corpus, clip)
    t0 = time.process_time()
    _, info = project(joints, Environment(g), residual=ResidualConfig(max_force=0.5),
                      normalizer=_normalizer(str(corpus)), flight=FlightConfig(), strength=strength_of(variant))
    return {"clip": clip, "g": g, "variant": variant, "success": info.success, "d_l2_pose": info.d_l2_pose,
            "residual_n": info.residual["force_mean_n"], "err_local_mm": info.err_local_mm,
            "cpu_s": time.process_time() - t0, "duration_s": info.duration_s}


def _med(rows: list[dict], key: str) -> float | None:
    vals = [r[key] for r in rows if r["success"] and r[key] is not None and np.isfinite(r[key])]
    return round(float(np.median(vals)), 2) if vals else None


def summarise(records: list[dict], gravities: list[float]) -> dict:
    """Per (g, variant): n, success rate, medians over tracked rollouts; also on the common tracked clips."""
    by = defaultdict(list)
    for r in records:
        variants = VARIANTS if r["g"] >= -9.81 else (r["variant"],)
        for v in variants:
            by[(r["g"], v)].append(r)
    table, common = [], []
    for g in gravities:
        ok_all = None
        for v in VARIANTS:
            rows = by.get((g, v), [])
            clips = {r["clip"] for r in rows if r["success"]}
            ok_all = clips if ok_all is None else ok_all & clips
            table.append({"g": g, "variant": v, "n": len(rows), "success": round(sum(r["success"] for r in rows) / max(len(rows), 1), 3),
                          "pose_d_l2_median": _med(rows, "d_l2_pose"), "residual_n_median": _med(rows, "residual_n"),
                          "err_local_mm_median": _med(rows, "err_local_mm"),
                          "cpu_s_per_pair": round(float(np.mean([r["cpu_s"] for r in rows])), 2) if rows else None})
        for v in VARIANTS:
            rows = [r for r in by.get((g, v), []) if r["clip"] in (ok_all or set())]
            common.append({"g": g, "variant": v, "n": len(rows), "pose_d_l2_median": _med(rows, "d_l2_pose"),
                           "residual_n_median": _med(rows, "residual_n"), "err_local_mm_median": _med(rows, "err_local_mm")})
    return {"table": table, "on_clips_tracked_by_every_variant": common}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--corpus", type=Path, required=True)
    ap.add_argument("--shards", type=Path, required=True, help="an augmentation run's shards/ (Earth results)")
    ap.add_argument("--log", type=Path, required=True, help="resumable .jsonl of every projection")
    ap.add_argument("--out", type=Path, default=Path("reports/augment/high_gravity.json"))
    ap.add_argument("--per-stratum", type=int, default=6)
    ap.add_argument("--gravities", type=float, nargs="+", default=[-9.81, -15.0, -18.0, -20.0])
    ap.add_argument("--variants", nargs="+", default=list(VARIANTS), choices=VARIANTS)
    args = ap.parse_args(argv)
    from simdiff.sim.pool import limit_threads

    limit_threads(1)
    chosen = args.log.with_suffix(".clips.json")  # the selection is frozen at the first run (shards grow)
    if chosen.is_file():
        clips = json.loads(chosen.read_text())
    else:
        clips = pick_clips(args.corpus, args.shards, args.per_stratum)
        chosen.parent.mkdir(parents=True, exist_ok=True)
        chosen.write_text(json.dumps(clips))
    selected = set(sum(clips.values(), []))
    done = set()
    if args.log.exists():
        done = {(r["clip"], r["g"], r["variant"]) for r in map(json.loads, args.log.read_text().splitlines()) if r}
    args.log.parent.mkdir(parents=True, exist_ok=True)
    tasks = [(c, g, v) for g in args.gravities for c in sum(clips.values(), [])
             for v in (("earth",) if g >= -9.81 else args.variants)]
    with args.log.open("a") as f:
        for k, (c, g, v) in enumerate(tasks):
            if (c, g, v) in done:
                continue
            rec = run_one(args.corpus, c, g, v)
            f.write(json.dumps(rec) + "\n")
            f.flush()
            print(f"[{k + 1}/{len(tasks)}] {c} g={g} {v}: ok={rec['success']} pose={rec['d_l2_pose']:.2f} "
                  f"res={rec['residual_n']:.0f}N local={rec['err_local_mm']:.0f}mm cpu={rec['cpu_s']:.1f}s", flush=True)
    records = [r for r in map(json.loads, filter(str.strip, args.log.read_text().splitlines())) if r["clip"] in selected]
    summary = {"clips": clips, "gravities": args.gravities, "variants": list(VARIANTS),
               "settings": "project(flight=FlightConfig(), residual max_force=0.5, corpus Mean/Std), 1 thread",
               **summarise(records, args.gravities)}
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(summary, indent=1))
    for row in summary["table"]:
        print(json.dumps(row))
    return 0


if __name__ == "__main__":
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    raise SystemExit(main())
