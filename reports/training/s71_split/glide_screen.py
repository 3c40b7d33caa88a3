"""Screen (no verdict): do a model's runs glide under g -1.6?
python glide_screen.py MODEL [--seed 7950] [--n 8] [--alpha A] [--edit-t T] [--foot-lock F] [--g G]

The model check's two run prompts x N samples, 120 frames, under Earth and g G (default -1.6) with the same noise (seeds S + prompt
index), the model's sampling.json (eta included; the options override it). Per environment: samples that glide
(simdiff.motion.metrics.glides: pelvis faster than 0.5 m/s while no foot joint's height changes by 0.05 m), that never
touch the floor, the median largest foot-joint lift (m) and the median pelvis speed (m/s). One JSON line."""
from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np
import torch

from simdiff.eval.model_check.config import SPEED_PROMPTS
from simdiff.eval.model_check.detect import root_speed
from simdiff.model.generator import MotionGenerator
from simdiff.motion.features import features_to_joints
from simdiff.motion.metrics import glides, never_touches
from simdiff.motion.skeleton import FOOT_LEFT, FOOT_RIGHT

FEET = [*FOOT_LEFT, *FOOT_RIGHT]


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("model")
    ap.add_argument("--seed", type=int, default=7950)
    ap.add_argument("--n", type=int, default=8)
    ap.add_argument("--alpha", type=float)
    ap.add_argument("--edit-t", type=int)
    ap.add_argument("--foot-lock", type=float)
    ap.add_argument("--g", type=float, default=-1.6, help="the low gravity, m/s² along z")
    a = ap.parse_args()
    torch.set_num_threads(2)
    s = json.loads((Path(a.model) / "sampling.json").read_text())
    for key in ("alpha", "edit_t", "foot_lock"):
        if getattr(a, key) is not None:
            s[key] = getattr(a, key)
    gen, t0 = MotionGenerator.load(a.model), time.time()
    out = {}
    for key, g in (("earth", -9.81), ("low_g", a.g)):
        joints = []
        for i, p in enumerate(SPEED_PROMPTS["run"]):
            f = gen.generate([p] * a.n, 120, seed=a.seed + i, steps=s["steps"], guidance=s["guidance"],
                             eta=s.get("eta", 0.0), alpha=s["alpha"], foot_lock=s["foot_lock"], env=[g, 0.0, 0.0],
                             env_guidance=s["env_guidance"], anchor=s.get("anchor", "adapters"),
                             anchor_alpha=s.get("anchor_alpha", 0.0),
                             **({"edit_t": s["edit_t"]} if "edit_t" in s else {})).features
            joints.append(features_to_joints(f.double()).numpy())
        j = np.concatenate(joints)
        lift = np.ptp(j[:, :, FEET, 1], axis=1).max(axis=1)
        speed = np.array([root_speed(x) for x in j])
        out[key] = {"n": len(j), "glides": int(glides(j).sum()), "never_touch": int(never_touches(j).sum()),
                    "foot_lift_median_m": round(float(np.median(lift)), 3),
                    "pelvis_speed_median": round(float(np.median(speed)), 3),
                    "pelvis_height_median_m": round(float(np.median(j[:, :, 0, 1])), 3)}
    print(json.dumps({"model": a.model, "sampling": s, "g": a.g, "seconds": round(time.time() - t0), **out}), flush=True)


if __name__ == "__main__":
    main()
