"""Foot-cleanup variants on a model's samples: generate once (lock off, cached), apply each variant, protocol metrics.

usage: python lockvar.py SPLIT N SEEDS(comma) VARIANTS(comma) MODEL CORPUS EVALUATOR OUT_DIR
variants: none | chan (the lock on the contact channels) | geo:MM[:V] / or:MM[:V] (the lock with planted = foot joint
within MM mm of the own floor [and slower than V m/s]; `or`: or the channels) | clr:MM[:V] (the lock, then the
swing clearance at MM mm, min speed V m/s, default 0.5). Generation: alpha 0.5, env guidance 2, DDIM 20, w 2.5, Earth.
"""
import json, sys, os
from pathlib import Path
import numpy as np, torch
torch.set_num_threads(2)
from simdiff.model import MotionGenerator
from simdiff.text.base import load_text_encoder
from simdiff.eval.evaluator import OurEvaluator, load_evaluator
from simdiff.data.humanml3d import HumanML3D
from simdiff.eval.protocol import generator_fn
from simdiff.eval.model_check.split import measure_split
from simdiff.eval.model_check.config import SplitOptions
from simdiff.motion.foot_lock import lock_feet, CONTACT_JOINTS
from simdiff.motion.features import features_to_joints, SLICES
from simdiff.motion.metrics import OWN_FLOOR_PERCENTILE

split = sys.argv[1]; n = int(sys.argv[2]); seeds = [int(s) for s in sys.argv[3].split(",")]
variants = sys.argv[4].split(",")
M, CORPUS, EVAL, OUT = sys.argv[5:9]
cache = Path(OUT) / f"cache_{split}"; cache.mkdir(parents=True, exist_ok=True)
gen = MotionGenerator.load(M, "cpu", load_text=False)
gen.text_encoder = load_text_encoder(gen.config.text_encoder, "cpu")
base = generator_fn(gen, env=[-9.81, 0, 0], alpha=0.5, sampler="ddim", steps=20, guidance=2.5, foot_lock=0.0, env_guidance=2.0)

def geo_planted(f, lens, tol, speed=None):
    j = features_to_joints(f.double())  # B T 22 3
    low = j[..., 1].min(-1).values
    floor = torch.stack([torch.quantile(low[b, :lens[b]], OWN_FLOOR_PERCENTILE / 100) for b in range(len(lens))])
    h = j[:, :, list(CONTACT_JOINTS), 1] - floor[:, None, None]
    p = h <= tol
    if speed is not None:
        xz = j[:, :, list(CONTACT_JOINTS)][..., [0, 2]]
        v = torch.zeros_like(h); v[:, 1:] = (xz[:, 1:] - xz[:, :-1]).norm(dim=-1) * 20
        p = p & (v <= speed)
    return p

def apply(var, f, lens):
    lens_t = torch.as_tensor(lens)
    if var == "none": return f
    if var == "chan": return lock_feet(f, lens_t, 1.0)
    if var.startswith("clr"):
        from simdiff.motion.foot_clearance import clear_swing_feet
        parts = var.split(":"); c = float(parts[1]) / 1000; v = float(parts[2]) if len(parts) > 2 else 0.5
        return clear_swing_feet(lock_feet(f, lens_t, 1.0), lens_t, 1.0, clearance=c, min_speed=v)
    kind, tol = var.split(":")[0], float(var.split(":")[1]) / 1000
    spd = float(var.split(":")[2]) if var.count(":") == 2 else None
    g = geo_planted(f, lens, tol, spd)
    c = f[..., SLICES["contacts"]] > 0.5
    p = g if kind == "geo" else (g | c)
    return lock_feet(f, lens_t, 1.0, planted=p)

out = {}
for var in variants:
    def fn(captions, lengths, seed):
        key = cache / f"{seed}.pt"
        if key.exists():
            f = torch.load(key)
        else:
            f = base(captions, lengths, seed); torch.save(f, key)
        return apply(var, f, lengths)
    model = load_evaluator(EVAL, "cpu")
    ev = OurEvaluator(model, load_text_encoder(model.config.text_encoder, "cpu"))
    ds = HumanML3D(CORPUS, split, seed=seeds[0])
    r = measure_split(ev, ds, fn, SplitOptions(split=split, n=n), seeds)
    g = r["generated"]
    row = {k: (g[k]["mean"], g[k].get("ci95")) for k in ("sliding_own_floor", "skate_ratio", "r_precision_top3", "fid", "own_floor", "sliding") if k in g}
    out[var] = row
    print(var, json.dumps({k: round(v[0], 4) for k, v in row.items()}), flush=True)
    gt = r["ground_truth"]; out["gt"] = {k: gt[k]["mean"] for k in ("sliding_own_floor", "skate_ratio", "r_precision_top3", "fid") if k in gt}
json.dump(out, open(Path(OUT) / f"variants_{split}_{n}_{sys.argv[3]}.json", "w"), indent=1)
print("gt", out["gt"])
