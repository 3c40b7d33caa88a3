"""Flights under gravity on the CMU jump clips (issue 13, item 2): with and without the flight clock.

Usage:
    nice -n 10 python benchmarks/bench_flight.py --workers 2 --out reports/augment/flight.jsonl
    python benchmarks/bench_flight.py --summary reports/augment/flight.jsonl

Per (clip, g, clock on/off): status, the longest simulated flight (s), the COM vertical speed
at its take-off (m/s), the COM apex gain over the take-off height (m), the ballistic
predictions 2·v/|g| and v²/2|g| for that speed, the rollout's time warp and mean residual.
Resumable: records already in ``--out`` are skipped.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from jsonl_runs import done_keys, run_appending, write_summary  # noqa: E402

JUMPS = ["13_11", "13_13", "13_19", "13_39", "13_40", "16_02", "16_03", "16_05", "16_06", "16_07", "16_09",
         "16_10", "49_03", "105_39", "105_40", "105_41", "105_42", "105_43", "105_44", "105_45", "105_46",
         "105_47", "105_48", "105_49", "105_50", "105_51", "105_52"]
"""CMU trials whose description says jump / forward jump / jump turn (descriptions.tsv), AMC + ASF here."""
GRAVITIES = [-1.6, -3.0, -5.0, -9.81, -15.0, -20.0]


def _com(model, qpos: np.ndarray) -> np.ndarray:
    import mujoco

    d = mujoco.MjData(model)
    out = np.zeros(len(qpos))
    for i, q in enumerate(qpos):
        d.qpos[:] = q
        mujoco.mj_kinematics(model, d)
        mujoco.mj_comPos(model, d)
        out[i] = d.subtree_com[1, 2]
    return out


def flight_record(model, res, g: float) -> dict:
    """Longest airborne run of a rollout and its ballistic comparison."""
    from simdiff.motion.flight import runs as true_runs

    runs = true_runs(res.airborne)
    rec = {"flight_s": 0.0, "takeoff_vz": None, "apex_gain_m": None}
    if not runs:
        return rec
    s, e = max(runs, key=lambda r: r[1] - r[0])
    dt = res.timestep
    z = _com(model, res.qpos[s : e + 1])
    vz = float((z[1] - z[0]) / dt) if len(z) > 1 else 0.0
    rec.update(flight_s=float((e - s) * dt), takeoff_vz=vz, apex_gain_m=float(z.max() - z[0]),
               landing_drop_m=float(z[0] - z[-1]), flight_start_s=float(s * dt), flight_end_s=float(e * dt))
    if vz > 0:
        rec.update(pred_flight_s=2 * vz / abs(g), pred_apex_gain_m=vz**2 / (2 * abs(g)))
    return rec


def run_task(task: tuple) -> dict:
    clip, g, clock, max_frames = task
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    import time

    from bench_sim_cmu import cmu_fps, load_clip

    from simdiff.sim.env import Environment
    from simdiff.sim.flight import FlightConfig
    from simdiff.sim.humanoid import load_model
    from simdiff.sim.retarget import make_reference
    from simdiff.sim.rollout import rollout

    t0 = time.process_time()
    m = load_model()
    joints = load_clip(clip, cmu_fps(), max_frames)
    ref = make_reference(m, joints, gravity=g)
    res = rollout(m, ref, Environment(g), flight=FlightConfig() if clock else None)
    rec = {"clip": clip, "g": g, "clock": clock, "status": res.status, "fall_time": res.fall_time,
           "duration_s": ref.duration, "sim_s": float(len(res.airborne) * res.timestep),
           "residual_mean_mg": res.residual_stats()["force_mean_mg"],
           "airborne_force_max_n": res.residual_stats()["airborne_force_max_n"]}
    rec.update(flight_record(m, res, g))
    # landed: the longest flight ended on the floor and the rollout went on ≥ 0.5 s to its end without a fall
    rec["landed_ok"] = bool(res.status == "ok" and rec.get("flight_end_s") is not None
                            and rec["sim_s"] - rec["flight_end_s"] >= 0.5)
    rec["cpu_s"] = time.process_time() - t0
    return rec


def summary(path: Path) -> dict:
    recs = [json.loads(x) for x in path.read_text().splitlines() if x.strip()]
    out: dict = {"records": len(recs)}
    for clock in (True, False):
        mine = [r for r in recs if r["clock"] == clock]
        key = "clock" if clock else "no_clock"
        by = {(r["clip"], r["g"]): r for r in mine}
        rows = {}
        for g in sorted({r["g"] for r in mine}):
            rs = [r for r in mine if r["g"] == g]
            ok = [r for r in rs if r["status"] == "ok"]
            landed = [r for r in rs if r.get("landed_ok")]
            ratio = [r["flight_s"] / by[(r["clip"], -9.81)]["flight_s"] for r in rs
                     if (r["clip"], -9.81) in by and by[(r["clip"], -9.81)]["flight_s"] > 0]
            fit_t = [r["flight_s"] / r["pred_flight_s"] for r in rs if r.get("pred_flight_s") and r["takeoff_vz"] > 0.5]
            fit_h = [r["apex_gain_m"] / r["pred_apex_gain_m"] for r in rs if r.get("pred_apex_gain_m") and r["takeoff_vz"] > 0.5]
            vz = [r["takeoff_vz"] for r in rs if r["takeoff_vz"] is not None]
            rows[str(g)] = {
                "clips": len(rs), "ok": len(ok), "ok_rate": len(ok) / len(rs) if rs else None,
                "landed_ok": len(landed) if all("landed_ok" in r for r in rs) else None,
                "flight_s_median": float(np.median([r["flight_s"] for r in rs])) if rs else None,
                "flight_ratio_vs_earth_median": float(np.median(ratio)) if ratio else None,
                "flight_ratio_ge3": int(sum(x >= 3 for x in ratio)),
                "takeoff_vz_median": float(np.median(vz)) if vz else None,
                "flight_over_ballistic_median": float(np.median(fit_t)) if fit_t else None,
                "flight_over_ballistic_within20": int(sum(abs(x - 1) <= 0.2 for x in fit_t)), "fit_n": len(fit_t),
                "apex_over_ballistic_median": float(np.median(fit_h)) if fit_h else None,
                "apex_over_ballistic_within20": int(sum(abs(x - 1) <= 0.2 for x in fit_h)),
                "cpu_s_per_sim_s": float(sum(r["cpu_s"] for r in rs) / max(sum(r["sim_s"] for r in rs), 1e-9)),
            }
        out[key] = rows
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", type=Path, default=Path("reports/augment/flight.jsonl"))
    ap.add_argument("--clips", nargs="*", default=JUMPS)
    ap.add_argument("--gravities", nargs="*", type=float, default=GRAVITIES)
    ap.add_argument("--no-baseline", action="store_true", help="skip the runs without the flight clock")
    ap.add_argument("--max-frames", type=int, default=196)
    ap.add_argument("--workers", type=int, default=1)
    ap.add_argument("--summary", type=Path, help="print the summary of a finished --out and exit")
    args = ap.parse_args(argv)
    if args.summary:
        return write_summary(args.summary, summary)
    done = done_keys(args.out, lambda r: (r["clip"], r["g"], r["clock"]))
    clocks = (True,) if args.no_baseline else (True, False)
    tasks = [(c, g, k, args.max_frames) for c in args.clips for g in args.gravities for k in clocks
             if (c, g, k) not in done]
    run_appending(tasks, run_task, args.out, args.workers, lambda rec: " ".join(str(v) for v in (
        rec["clip"], rec["g"], rec["clock"], rec["status"], round(rec["flight_s"], 3), rec.get("takeoff_vz"))))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
