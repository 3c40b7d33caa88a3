"""Physical response to φ and speed of the projection.

Usage:
    nice -n 10 python benchmarks/bench_sim_response.py --out reports/sim/response.json

* gravity: CMU jumps 16_05, 16_06 and jacks 13_30 at g = −3, −9.81, −15: COM apex, longest
  airborne phase, total airborne time, take-off speed (COM v_z at the start of the longest flight);
* wind: walk 16_15 and jump 16_05 under ±10 N along HumanML3D x and z: horizontal COM
  drift at the end relative to the windless rollout (m);
* speed: CPU seconds per second of motion for retarget and simulation (one core), and the
  process pool's wall time with 1 and 2 workers on the same clips (``--pool-clips``, default
  the first 16 CMU clips; ``--pool-only`` reruns just that part).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_sim_cmu import cmu_fps, load_clip  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]


def com_track(model, qpos: np.ndarray) -> np.ndarray:
    import mujoco

    d = mujoco.MjData(model)
    out = np.zeros((qpos.shape[0], 3))
    for i, q in enumerate(qpos):
        d.qpos[:] = q
        mujoco.mj_kinematics(model, d)
        mujoco.mj_comPos(model, d)
        out[i] = d.subtree_com[1]
    return out


def flight_stats(model, res) -> dict:
    dt = res.timestep
    com = com_track(model, res.qpos[::5])  # every 5 steps (90 Hz) for the apex
    air = res.airborne
    runs, start = [], None
    for i, a in enumerate(np.append(air, False)):
        if a and start is None:
            start = i
        elif not a and start is not None:
            runs.append((start, i))
            start = None
    longest = max(runs, key=lambda r: r[1] - r[0]) if runs else None
    takeoff = None
    if longest is not None:
        c = com_track(model, res.qpos[longest[0] : longest[0] + 2])
        takeoff = float((c[1, 2] - c[0, 2]) / dt)
    return {
        "status": res.status,
        "apex_m": float(com[:, 2].max()),
        "air_total_s": float(air.sum() * dt),
        "air_longest_s": 0.0 if longest is None else float((longest[1] - longest[0]) * dt),
        "takeoff_vz": takeoff,
        "residual_mean_mg": res.residual_stats()["force_mean_mg"],
    }


def pool_timing(n_clips: int, max_frames: int) -> dict:
    """Wall seconds of :class:`ProjectionPool` with 1 and 2 worker processes on the same clips.

    The clips must take much longer than a worker's start (interpreter, imports, humanoid:
    about 2 s), or the pool measures its own start-up.
    """
    from bench_sim_cmu import clip_list

    from simdiff.sim.pool import PoolConfig, ProjectionPool

    fps = cmu_fps()
    motions = [load_clip(c, fps, max_frames) for c in clip_list(n_clips)]
    rec = {}
    for w in (1, 2):
        t0 = time.perf_counter()
        with ProjectionPool(PoolConfig(workers=w)) as pool:  # timing includes the workers' start-up
            pool.map(motions)
        rec[str(w)] = time.perf_counter() - t0
        print("pool", w, rec[str(w)], flush=True)
    return {"pool_wall_s": rec, "pool_motion_s": float(sum((len(x) - 1) / 20 for x in motions)),
            "pool_clips": n_clips}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", type=Path, default=ROOT / "reports" / "sim" / "response.json")
    ap.add_argument("--max-frames", type=int, default=196)
    ap.add_argument("--skip-pool", action="store_true")
    ap.add_argument("--pool-only", action="store_true", help="only the pool timing, merged into --out")
    ap.add_argument("--pool-clips", type=int, default=16, help="clips for the pool timing (first of the CMU list)")
    args = ap.parse_args(argv)
    if args.pool_only:
        out = json.loads(args.out.read_text()) if args.out.exists() else {}
        out.update(pool_timing(args.pool_clips, args.max_frames))
        args.out.write_text(json.dumps(out, indent=1))
        return 0

    from simdiff.sim.retarget import make_reference
    from simdiff.sim.env import Environment
    from simdiff.sim.humanoid import load_model
    from simdiff.sim.rollout import rollout

    m = load_model()
    fps = cmu_fps()
    clips = {c: load_clip(c, fps, args.max_frames) for c in ("16_05", "16_06", "13_30", "16_15")}
    refs = {}
    speed = []
    for c, j in clips.items():
        t0 = time.process_time()
        refs[c] = make_reference(m, j)
        speed.append({"clip": c, "duration_s": refs[c].duration, "retarget_cpu_s": time.process_time() - t0})
    out: dict = {"gravity": {}, "wind": {}, "speed": speed}
    for c in ("16_05", "16_06", "13_30"):
        for g in (-3.0, -9.81, -15.0):
            ref = refs[c] if g == -9.81 else make_reference(m, clips[c], gravity=g)  # ID feed-forward under g
            res = rollout(m, ref, Environment(g))
            out["gravity"][f"{c}@{g}"] = flight_stats(m, res)
            if g == -9.81:
                for s in speed:
                    if s["clip"] == c:
                        s["sim_cpu_s"] = res.cpu_s
            print(c, g, out["gravity"][f"{c}@{g}"], flush=True)
    for c in ("16_15", "16_05"):
        base = rollout(m, refs[c], Environment())
        base_end = com_track(m, base.qpos[-1:])[0]
        for wx, wy in ((10, 0), (-10, 0), (0, 10), (0, -10)):
            res = rollout(m, refs[c], Environment(-9.81, wx, wy))
            n = min(res.qpos.shape[0], base.qpos.shape[0]) - 1
            end = com_track(m, res.qpos[n : n + 1])[0]
            ref_end = com_track(m, base.qpos[n : n + 1])[0]
            # world x = HumanML3D z, world y = HumanML3D x
            drift_hml = {"x": float(end[1] - ref_end[1]), "z": float(end[0] - ref_end[0])}
            rec = {"status": res.status, "base_status": base.status, "t_end_s": n * res.timestep,
                   "drift_m": drift_hml, "residual_mean_mg": res.residual_stats()["force_mean_mg"]}
            out["wind"][f"{c}@({wx},{wy})"] = rec
            print(c, wx, wy, rec, flush=True)
        del base_end
    if not args.skip_pool:
        out.update(pool_timing(args.pool_clips, args.max_frames))
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(out, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
