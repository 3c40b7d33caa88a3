"""Scaling of the augmentation driver: ``--backend ray`` with 1 and 2 workers, the process pool beside it.

Usage:
    nice -n 10 python benchmarks/bench_augment_ray.py --corpus /path/to/corpus --clips 16 \
        --out ray_scaling.json

The same fixed sample of pairs goes through :func:`simdiff.data.augment.run.augment` once per
configuration (backend × workers), each in a fresh Python process and a fresh output folder:
``--clips`` training clips drawn with ``--seed`` from the corpus's train split, cut to their
first ``--max-frames`` frames (20 fps), binary mode (Earth only, one pair per clip), shards of
``--shard-size`` clips. ``process:1`` is what ``--workers 1`` does: no pool, the simulations run
in the driver process. Without ``--corpus`` a synthetic corpus
(:func:`simdiff.eval.testing.write_tiny_corpus`) is written into a temporary folder.

Before the clock starts, every configuration warms its workers up (Ray started, worker processes
spawned, simulator imported) by projecting 2 × ``workers`` 2-s motions; that start-up time is
reported apart (``startup_s``). ``--repeats`` runs the configurations that many times, interleaved;
the speed-up uses the median wall time. Measured per configuration: wall seconds of the run, simulator
CPU seconds (the per-pair ``cpu_s`` the workers record: retarget + rollout + metrics, process
time), simulated seconds (rollout frames / 20), CPU s per simulated s, and a digest of the
kept ids and rollout lengths (the simulation is deterministic: every configuration must give the
same). ``speedup`` = wall(1 worker) / wall(2 workers) per backend. The host's load average
before and after each run says whether the cores were shared.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

CONFIGS: tuple[tuple[str, int], ...] = (("ray", 1), ("ray", 2), ("process", 1), ("process", 2))


def sample_corpus(corpus: Path, root: Path, clips: int, seed: int, max_frames: int) -> Path:
    """A corpus folder under ``root`` holding ``clips`` train clips of ``corpus`` cut to ``max_frames``."""
    from simdiff.data.humanml3d import read_split
    from simdiff.errors import SimdiffError

    ids = read_split(corpus / "train.txt")
    if len(ids) < clips:
        raise SimdiffError(f"{corpus / 'train.txt'}: {len(ids)} clips, fewer than --clips {clips}")
    chosen = sorted(np.random.default_rng(seed).choice(len(ids), size=clips, replace=False).tolist())
    out = root / "corpus"
    for sub in ("new_joint_vecs", "new_joints", "texts"):
        (out / sub).mkdir(parents=True, exist_ok=True)
    names = []
    for i in chosen:
        clip = ids[i]
        names.append(clip)
        for sub in ("new_joint_vecs", "new_joints"):
            path = corpus / sub / f"{clip}.npy"
            if path.is_file():
                np.save(out / sub / f"{clip}.npy", np.load(path)[: max_frames - 1])
        (out / "texts" / f"{clip}.txt").write_bytes((corpus / "texts" / f"{clip}.txt").read_bytes())
    for name in ("Mean.npy", "Std.npy"):
        (out / name).write_bytes((corpus / name).read_bytes())
    (out / "train.txt").write_text("\n".join(names) + "\n", encoding="utf-8")
    return out


def run_one(corpus: Path, out: Path, backend: str, workers: int, shard_size: int) -> dict[str, Any]:
    """One configuration in this process: warm up, then time :func:`augment` (binary mode)."""
    from simdiff.data.augment import AugmentConfig, FilterConfig, augment
    from simdiff.data.augment.projector import SimProjector
    from simdiff.data.augment.pairs import load_source_joints
    from simdiff.data.humanml3d import read_split
    from simdiff.sim.env import Environment

    load_before = os.getloadavg()
    t0 = time.perf_counter()
    proj = SimProjector(str(corpus), workers=workers, backend=backend)
    first = load_source_joints(corpus, read_split(corpus / "train.txt")[0])[:40]
    list(proj([first] * (2 * workers), [Environment()] * (2 * workers)))
    startup = time.perf_counter() - t0
    config = AugmentConfig(mode="binary", shard_size=shard_size, workers=workers, backend=backend,
                           filter=FilterConfig(max_pose_d_l2=1e9, max_residual_n=1e9))
    t1 = time.perf_counter()
    try:
        report = augment(corpus, out, config, projector=proj, progress=False)
    finally:
        proj.close()
    wall = time.perf_counter() - t1
    records = [r for p in sorted((out / "shards").glob("*.json"))
               for r in json.loads(p.read_text(encoding="utf-8"))["records"]]
    sim_s = sum(float(r["info"].get("n_out", 0)) / 20.0 for r in records if isinstance(r["info"], dict))
    digest = hashlib.sha256(json.dumps(sorted((r["id"], r["written"], (r["info"] or {}).get("n_out")
                                               if isinstance(r["info"], dict) else str(r["info"]))
                                              for r in records)).encode()).hexdigest()[:16]
    return {"backend": backend, "workers": workers, "pairs": report["pairs"],
            "tracked": sum(1 for r in records if r["written"]), "startup_s": round(startup, 2),
            "wall_s": round(wall, 2), "sim_cpu_s": report["sim_cpu_s_total"], "simulated_s": round(sim_s, 2),
            "cpu_s_per_sim_s": report["cpu_s_per_sim_s"],
            "wall_s_per_sim_s": round(wall / sim_s, 4) if sim_s else None,
            "load_before": [round(x, 2) for x in load_before], "load_after": [round(x, 2) for x in os.getloadavg()],
            "digest": digest}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--corpus", type=Path, help="source corpus (HumanML3D layout); default: a synthetic one")
    ap.add_argument("--clips", type=int, default=16, help="training clips in the sample (default 16)")
    ap.add_argument("--max-frames", type=int, default=120, help="frames kept per clip, 20 fps (default 120 = 6 s)")
    ap.add_argument("--shard-size", type=int, default=8, help="clips per shard (default 8)")
    ap.add_argument("--seed", type=int, default=0, help="seed of the clip sample (default 0)")
    ap.add_argument("--configs", nargs="+", default=[f"{b}:{w}" for b, w in CONFIGS],
                    help="backend:workers to run (default ray:1 ray:2 process:1 process:2)")
    ap.add_argument("--repeats", type=int, default=1, help="runs per configuration, interleaved (default 1)")
    ap.add_argument("--out", type=Path, default=Path("ray_scaling.json"),
                    help="result JSON (default ./ray_scaling.json)")
    ap.add_argument("--one", nargs=4, metavar=("CORPUS", "OUT", "BACKEND", "WORKERS"), help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.one:
        corpus, out, backend, workers = args.one
        print(json.dumps(run_one(Path(corpus), Path(out), backend, int(workers), args.shard_size)))
        return 0
    runs = []
    with tempfile.TemporaryDirectory(prefix="bench_ray_") as tmp:
        root = Path(tmp)
        if args.corpus is None:
            from simdiff.eval.testing import write_tiny_corpus

            src = write_tiny_corpus(root / "synthetic", n_train=args.clips, n_test=1, frames=args.max_frames)
        else:
            src = args.corpus
        corpus = sample_corpus(src, root, args.clips, args.seed, args.max_frames)
        for spec in [c for _ in range(args.repeats) for c in args.configs]:
            backend, workers = spec.split(":")
            out = root / f"out_{backend}_{workers}_{len(runs)}"
            proc = subprocess.run([sys.executable, __file__, "--shard-size", str(args.shard_size), "--one", str(corpus),
                                   str(out), backend, workers], capture_output=True, text=True)
            if proc.returncode != 0:
                print(proc.stderr[-2000:], file=sys.stderr)
                return proc.returncode
            runs.append(json.loads(proc.stdout.strip().splitlines()[-1]))
            print(json.dumps(runs[-1]), file=sys.stderr)
    speedup = {}
    for backend in sorted({r["backend"] for r in runs}):
        wall = {w: float(np.median([r["wall_s"] for r in runs if r["backend"] == backend and r["workers"] == w]))
                for w in {r["workers"] for r in runs if r["backend"] == backend}}
        if 1 in wall and 2 in wall:
            speedup[backend] = round(wall[1] / wall[2], 3)
    try:
        import ray

        ray_version = ray.__version__
    except ImportError:
        ray_version = None
    result = {"settings": {"corpus": args.corpus.name if args.corpus else "synthetic", "clips": args.clips,
                           "max_frames": args.max_frames, "shard_size": args.shard_size, "seed": args.seed, "repeats": args.repeats,
                           "mode": "binary (Earth only)", "cpu_count": os.cpu_count(), "python": platform.python_version(),
                           "ray": ray_version},
              "runs": runs, "speedup_2_vs_1": speedup,
              "same_results": len({r["digest"] for r in runs}) == 1}
    args.out.parent.mkdir(parents=True, exist_ok=True)
    tmp_out = args.out.with_suffix(".json.tmp")
    tmp_out.write_text(json.dumps(result, indent=1) + "\n", encoding="utf-8")
    os.replace(tmp_out, args.out)
    print(json.dumps({"speedup_2_vs_1": speedup, "same_results": result["same_results"]}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
