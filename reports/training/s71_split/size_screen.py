"""Screen (no verdict): stage A's gravity sizes on probe seeds, with the simulator.
python size_screen.py MODEL [--seed 7700] [--n 8] [--eta 1] [--save FILE.npz]

The model check's six jump prompts x N samples, 120 frames, under Earth and g -1.6 with the same noise (seeds S +
prompt index, as s67_ballistic/ballistic_screen.py, so its flight figures are the same samples), the model's
sampling.json (fallback not applied). Then the model check's own gravity response
(simdiff.eval.model_check.response.gravity_response: the Earth sample re-tracked under Earth and g -1.6 by the
simulator's projector, 2 worker processes): pairs rising in both, median generated/simulated size of the apex-gain
and flight-time changes with their 95 % bootstrap intervals. One JSON line on stdout."""
from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np
import torch

from simdiff.data.augment.projector import SimProjector
from simdiff.eval.model_check.config import JUMP_PROMPTS
from simdiff.eval.model_check.response import gravity_response
from simdiff.model.generator import MotionGenerator
from simdiff.motion.features import features_to_joints


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("model")
    ap.add_argument("--seed", type=int, default=7700)
    ap.add_argument("--n", type=int, default=8)
    ap.add_argument("--eta", type=float, default=1.0)
    ap.add_argument("--save", default=None, help="write the Earth and low-g joints here (npz)")
    ap.add_argument("--load", default=None, help="re-use joints saved by --save (no generation)")
    a = ap.parse_args()
    torch.set_num_threads(2)
    s = json.loads((Path(a.model) / "sampling.json").read_text())
    t0 = time.time()
    if a.load:
        z = np.load(a.load)
        earth, moon = z["earth"], z["moon"]
    else:
        gen = MotionGenerator.load(a.model)
        sets: dict[str, list[np.ndarray]] = {"earth": [], "moon": []}
        for i, p in enumerate(JUMP_PROMPTS):
            for key, g in (("earth", -9.81), ("moon", -1.6)):
                f = gen.generate([p] * a.n, 120, seed=a.seed + i, steps=s["steps"], guidance=s["guidance"],
                                 eta=a.eta, alpha=s["alpha"], foot_lock=s["foot_lock"], env=[g, 0.0, 0.0],
                                 env_guidance=s["env_guidance"], anchor=s.get("anchor", "adapters"),
                                 anchor_alpha=s.get("anchor_alpha", 0.0),
                                 **({"edit_t": s["edit_t"]} if "edit_t" in s else {})).features
                sets[key].append(features_to_joints(f).numpy())
        earth, moon = (np.concatenate(sets[k]).astype(np.float32) for k in ("earth", "moon"))
        if a.save:
            np.savez_compressed(a.save, earth=earth, moon=moon)
    t1 = time.time()
    ids = [f"p{i}_s{j}" for i in range(len(JUMP_PROMPTS)) for j in range(a.n)]
    proj = SimProjector(None, 2, "process", 0.5)
    try:
        r = gravity_response(ids, earth, moon, -1.6, proj, seed=0)
    finally:
        getattr(proj, "close", lambda: None)()
    ra = r["ratios"]
    out = {"model": a.model, "seed": a.seed, "eta": a.eta, "sampling": s, "gen_s": round(t1 - t0),
           "sim_s": round(time.time() - t1), "n": r["n"], "rise_both": r["rise_both"],
           "never_touch_low_g": r["never_touch"]["low_g"], "glides_low_g": r["glides"]["low_g"],
           **{f"{k}_size": round(ra[k]["median_ratio"], 3) for k in ra},
           **{f"{k}_ci95": [round(v, 3) for v in ra[k]["ci95"]] for k in ra},
           **{f"{k}_n": ra[k]["n_ratio"] for k in ra},
           **{f"{k}_gen_change": ra[k]["generated_change"] for k in ra},
           **{f"{k}_sim_change": ra[k]["simulated_change"] for k in ra}}
    print(json.dumps(out), flush=True)


if __name__ == "__main__":
    main()
