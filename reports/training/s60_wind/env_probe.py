"""Generated-only physics probe (no simulator): python env_probe.py [--walks N] [--jumps N] [--seed S] MODEL...

Wind: the two val walk prompts of the model check x N samples, each under Earth and under (w_x, w_y) = (+10, 0),
(-10, 0), (0, +10), (0, -10) N with the same noise; a sample drifts downwind when its root displacement along the
wind grows against Earth (the check's rule, :func:`simdiff.eval.response.quantities`). Gravity: the six jump
prompts x N samples under Earth and g -1.6; medians of the generated change of apex gain and of the longest flight
(the simulator's side of the check's size ratios is not computed here). Shipped sampling settings of each model
(sampling.json, its anchor and anchor_alpha included since session 66, ballistic since 67; fallback not applied;
--env-guidance overrides s_e), 120 frames, seeds S + prompt index.
Ordinary motions under low gravity (--moon N, session 61): the two walk and two run prompts x N under Earth and g -1.6
with the same noise; mean floating (mm, the model check's metric) at g -1.6 and at Earth, the median ratio of root
speeds (g -1.6 over Earth) and (since session 71) the samples that glide at g -1.6 (the model check's rule), seeds S + 200
+ prompt index: a 1-minute screen for what stage C' (val captions at
g -1.6) penalises."""
from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np
import torch

from simdiff.eval.model_check.config import JUMP_PROMPTS, SPEED_PROMPTS
from simdiff.eval.model_check.detect import root_speed
from simdiff.eval.response import quantities
from simdiff.model.generator import MotionGenerator
from simdiff.motion.features import features_to_joints
from simdiff.motion.flight import flight_stats
from simdiff.motion.metrics import glides, per_sample_physics_metrics

WINDS = [(-9.81, 10.0, 0.0), (-9.81, -10.0, 0.0), (-9.81, 0.0, 10.0), (-9.81, 0.0, -10.0)]


def joints(gen: MotionGenerator, prompt: str, n: int, seed: int, env, s: dict) -> np.ndarray:
    out = gen.generate([prompt] * n, 120, seed=seed, steps=s["steps"], guidance=s["guidance"], alpha=s["alpha"],
                       foot_lock=s["foot_lock"], env=list(env), env_guidance=s["env_guidance"],
                       anchor=s.get("anchor", "adapters"), anchor_alpha=s.get("anchor_alpha", 0.0),  # session 66
                       ballistic=s.get("ballistic", 0.0),  # session 67
                       **({"edit_t": s["edit_t"]} if "edit_t" in s else {}),  # session 70
                       eta=s.get("eta", 0.0))  # session 70
    return features_to_joints(out.features.double()).numpy()


def probe(model: str, walks: int, jumps: int, seed: int, env_guidance: float | None = None, moon_n: int = 0) -> dict:
    s = json.loads((Path(model) / "sampling.json").read_text())
    if env_guidance is not None:
        s["env_guidance"] = env_guidance
    gen, t0 = MotionGenerator.load(model), time.time()
    wind = {f"wx{w[1]:+.0f} wy{w[2]:+.0f}": [] for w in WINDS}
    for i, p in enumerate(SPEED_PROMPTS["walk"] if walks else ()):
        earth = joints(gen, p, walks, seed + i, (-9.81, 0.0, 0.0), s)
        for w, key in zip(WINDS, wind):
            windy = joints(gen, p, walks, seed + i, w, s)
            wind[key] += [quantities(a, w)["drift_along_wind_m"] - quantities(b, w)["drift_along_wind_m"]
                          for a, b in zip(windy, earth)]
    apex, flight = [], []
    for i, p in enumerate(JUMP_PROMPTS if jumps else ()):
        earth = joints(gen, p, jumps, seed + 100 + i, (-9.81, 0.0, 0.0), s)
        moon = joints(gen, p, jumps, seed + 100 + i, (-1.6, 0.0, 0.0), s)
        for a, b in zip(moon, earth):
            fa, fb = flight_stats(a), flight_stats(b)
            apex.append(fa["apex_gain_m"] - fb["apex_gain_m"])
            flight.append(fa["flight_s"] - fb["flight_s"])
    floats: dict[str, list[float]] = {"moon": [], "earth": []}
    ratio, glide = [], 0
    for i, p in enumerate((*SPEED_PROMPTS["walk"], *SPEED_PROMPTS["run"]) if moon_n else ()):
        earth = joints(gen, p, moon_n, seed + 200 + i, (-9.81, 0.0, 0.0), s)
        low = joints(gen, p, moon_n, seed + 200 + i, (-1.6, 0.0, 0.0), s)
        floats["earth"] += list(per_sample_physics_metrics(earth)["floating"])
        floats["moon"] += list(per_sample_physics_metrics(low)["floating"])
        ratio += [root_speed(a) / max(root_speed(b), 1e-6) for a, b in zip(low, earth)]
        glide += int(glides(low).sum())  # session 71: rule 83's runs glided under g -1.6 past this screen
    res = {"model": model, "seconds": round(time.time() - t0),
           "wind": {k: {"downwind": int(sum(d > 0 for d in v)), "n": len(v), "median_m": float(np.median(v))}
                    for k, v in wind.items() if v}}
    if apex:
        res["gravity"] = {"n": len(apex), "apex_change_median_m": float(np.median(apex)),
                          "flight_change_median_s": float(np.median(flight)),
                          "rise_both": int(sum(a > 0 and f > 0 for a, f in zip(apex, flight)))}
    if ratio:
        res["moon"] = {"n": len(ratio), "floating_mm": float(np.mean(floats["moon"])),
                       "earth_floating_mm": float(np.mean(floats["earth"])), "speed_ratio_median": float(np.median(ratio)),
                       "glides_low_g": glide}
    return res


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("models", nargs="+")
    ap.add_argument("--walks", type=int, default=8)
    ap.add_argument("--jumps", type=int, default=0)
    ap.add_argument("--seed", type=int, default=7000)
    ap.add_argument("--moon", type=int, default=0, help="walk/run samples per prompt under g -1.6 and Earth")
    ap.add_argument("--env-guidance", type=float, default=None, help="s_e instead of the model's sampling.json value")
    a = ap.parse_args()
    torch.set_num_threads(2)
    for m in a.models:
        r = probe(m, a.walks, a.jumps, a.seed, a.env_guidance, a.moon)
        total = sum(v["downwind"] for v in r["wind"].values()), sum(v["n"] for v in r["wind"].values())
        print(json.dumps(r), flush=True)
        print(f"{m} (s_e {a.env_guidance or 'shipped'}): wind {total[0]}/{total[1]}", " ".join(f"{k}:{v['downwind']}/{v['n']} {v['median_m']:+.3f}"
              for k, v in r["wind"].items()), r.get("gravity", ""), r.get("moon", ""), f"{r['seconds']}s",
              flush=True)
