"""Screen (no simulator, no verdict): what the ballistic flight projection does to a model's jumps.
python ballistic_screen.py MODEL [--seed S] [--n N] [--env-guidance SE] [--eta ETA] [--dump FILE]

The six jump prompts of the model check x N samples, 120 frames, under Earth and g -1.6 with the same noise (seeds
S + prompt index), the model's sampling.json settings (anchor included; fallback not applied). For the raw samples
and for them after :func:`simdiff.motion.ballistic.ballistic_flights` (each under its own g): median change of apex
gain and longest flight (g -1.6 minus Earth, per pair), pairs rising in both, and at Earth the share of samples the
check counts as jumps (flight >= 0.2 s, apex gain >= 0.15 m)."""
from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np
import torch

from simdiff.eval.model_check.config import JUMP_PROMPTS
from simdiff.model.generator import MotionGenerator
from simdiff.motion.ballistic import ballistic_flights
from simdiff.motion.features import features_to_joints
from simdiff.motion.flight import flight_stats


def stats(earth: list[dict], moon: list[dict]) -> dict:
    apex = [m["apex_gain_m"] - e["apex_gain_m"] for e, m in zip(earth, moon)]
    fl = [m["flight_s"] - e["flight_s"] for e, m in zip(earth, moon)]
    return {"n": len(apex), "apex_change_median_m": round(float(np.median(apex)), 3),
            "apex_change_iqr_m": [round(float(v), 3) for v in np.percentile(apex, [25, 75])],
            "flight_change_median_s": round(float(np.median(fl)), 3),
            "rise_both": int(sum(a > 0 and f > 0 for a, f in zip(apex, fl))),
            "earth_jumps": int(sum(e["flight_s"] >= 0.2 - 1e-9 and e["apex_gain_m"] >= 0.15 for e in earth)),
            "moon_apex_median_m": round(float(np.median([m["apex_gain_m"] for m in moon])), 3),
            "earth_apex_median_m": round(float(np.median([e["apex_gain_m"] for e in earth])), 3)}


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("model")
    ap.add_argument("--seed", type=int, default=7700)
    ap.add_argument("--n", type=int, default=8)
    ap.add_argument("--env-guidance", type=float, default=None)
    ap.add_argument("--eta", type=float, default=0.0, help="DDIM eta (session 70; 0: deterministic, as shipped)")
    ap.add_argument("--dump", default=None, help="write every sample's flight stats here (JSON)")
    a = ap.parse_args()
    torch.set_num_threads(2)
    s = json.loads((Path(a.model) / "sampling.json").read_text())
    if a.env_guidance is not None:
        s["env_guidance"] = a.env_guidance
    gen, t0 = MotionGenerator.load(a.model), time.time()
    out: dict[str, dict[str, list]] = {k: {"earth": [], "moon": []} for k in ("raw", "ballistic")}
    for i, p in enumerate(JUMP_PROMPTS):
        for key, g in (("earth", -9.81), ("moon", -1.6)):
            f = gen.generate([p] * a.n, 120, seed=a.seed + i, steps=s["steps"], guidance=s["guidance"], eta=a.eta,
                             alpha=s["alpha"], foot_lock=s["foot_lock"], env=[g, 0.0, 0.0],
                             env_guidance=s["env_guidance"], anchor=s.get("anchor", "adapters"),
                             anchor_alpha=s.get("anchor_alpha", 0.0),
                             **({"edit_t": s["edit_t"]} if "edit_t" in s else {})).features.double()
            for kind, feats in (("raw", f), ("ballistic", ballistic_flights(f, g))):
                out[kind][key] += [flight_stats(j) for j in features_to_joints(feats).numpy()]
    res = {"model": a.model, "s_e": s["env_guidance"], "seed": a.seed, "seconds": round(time.time() - t0),
           **({"anchor": "edit", "edit_t": s["edit_t"]} if "edit_t" in s else {}), **({"eta": a.eta} if a.eta else {})}
    res.update({k: stats(v["earth"], v["moon"]) for k, v in out.items()})
    print(json.dumps(res), flush=True)
    if a.dump:
        Path(a.dump).write_text(json.dumps(out))


if __name__ == "__main__":
    main()
