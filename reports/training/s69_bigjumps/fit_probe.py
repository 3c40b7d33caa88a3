"""Session 69: can the adapters *represent* the simulator's large low-gravity jumps? (a denoising probe, not sampling)

For low-gravity replays (g in [-2.0, -1.2]) in an augmented folder whose Earth twin's apex gain is >= --min-earth-apex,
take a --frames window (80) around the replay's pelvis peak (the same frames of its Earth twin), noise both at t with one
noise draw, and read the apex gain of the network's x̂₀ (alpha 1, as in training; the caption's table embedding):
  lowg->phi   x_t of the low-g replay, the low-g φ        (the training target at that x_t)
  lowg->earth x_t of the low-g replay, Earth φ
  earth->phi  x_t of the Earth twin, the low-g φ          (what the answer has to do from an Earth-like x_t)
Prints medians per t beside the targets. python fit_probe.py MODEL [MODEL ...] --data AUG [--n 32]"""
import argparse, functools, json
from pathlib import Path

import numpy as np
import torch

from simdiff.diffusion.ddpm import DDPMScheduler
from simdiff.model.checkpoint import load_pretrained
from simdiff.model.condition import Condition
from simdiff.motion.features import features_to_joints
from simdiff.motion.flight import flight_stats
from simdiff.text.table import open_caption_table

ap = argparse.ArgumentParser()
ap.add_argument("models", nargs="+", type=Path)
ap.add_argument("--data", type=Path, default=Path("/work/scratch/s67/aug_lowg"))
ap.add_argument("--min-earth-apex", type=float, default=0.25)
ap.add_argument("--n", type=int, default=32)
ap.add_argument("--frames", type=int, default=80, help="window (replays shorter than this are skipped)")
ap.add_argument("--t", type=int, nargs="+", default=[100, 300, 500, 700, 900])
ap.add_argument("--seed", type=int, default=69)
ap.add_argument("--text-table", type=Path, default=Path("/work/main/.gpu/captions.safetensors"))
a = ap.parse_args()
torch.set_num_threads(2)
root = a.data
env = json.loads((root / "env.json").read_text())
@functools.lru_cache(maxsize=None)
def joints(k: str) -> np.ndarray:
    """(T, 22, 3) joints of item k, read once."""
    return np.load(root / "new_joints" / f"{k}.npy")


by: dict[str, dict] = {}
for k, v in env.items():
    by.setdefault(v["source"], {})[k] = v
rows = []
for src, d in sorted(by.items()):
    e = [k for k, v in d.items() if v["factor"] == "earth"]
    if not e or flight_stats(joints(e[0]))["apex_gain_m"] < a.min_earth_apex:
        continue
    for k, v in sorted(d.items()):
        n = min(len(joints(k)), len(joints(e[0])))
        if v["factor"] == "gravity" and -2.0 <= v["env"][0] <= -1.2 and n >= a.frames:
            rows.append((k, e[0], v["env"][0]))
rng = np.random.default_rng(a.seed)
rows = [rows[i] for i in sorted(rng.choice(len(rows), size=min(a.n, len(rows)), replace=False))]
W = a.frames
items = []
for k, ek, g in rows:
    fl, fe = np.load(root / "new_joint_vecs" / f"{k}.npy"), np.load(root / "new_joint_vecs" / f"{ek}.npy")
    n = min(len(fl), len(fe))
    peak = int(np.argmax(joints(k)[:n, 0, 1]))
    s = max(0, min(n - W, peak - W // 2))
    cap = (root / "texts" / f"{k}.txt").read_text().splitlines()[0].split("#")[0]
    items.append((fl[:n][s:s + W], fe[:n][s:s + W], g, cap))
L = min(len(x[0]) for x in items)
low = np.stack([x[0][:L] for x in items]).astype(np.float32)
earth = np.stack([x[1][:L] for x in items]).astype(np.float32)
gs = torch.tensor([x[2] for x in items], dtype=torch.float32)
apex = lambda f: float(np.median([flight_stats(j)["apex_gain_m"] for j in f]))
print(f"{len(items)} low-g replays (g median {gs.median():.2f}) of {len(set(r[1] for r in rows))} Earth sources with apex >= "
      f"{a.min_earth_apex} m, {L} frames; target apex gain: low-g {apex(features_to_joints(low)):.3f} m, "
      f"Earth twin {apex(features_to_joints(earth)):.3f} m")
sched = DDPMScheduler()
for folder in a.models:
    net, cfg, extra = load_pretrained(folder, "cpu")
    net.eval()
    mean, std = extra["normalizer.mean"], extra["normalizer.std"]
    table = open_caption_table(a.text_table, cfg.text_encoder, "cpu")
    text = table.encode([x[3] for x in items])
    b = len(items)
    phi = torch.stack([gs, torch.zeros(b), torch.zeros(b)], dim=-1)
    erth = torch.tensor([-9.81, 0.0, 0.0]).expand(b, 3)
    xl, xe = (torch.from_numpy(low) - mean) / std, (torch.from_numpy(earth) - mean) / std
    out = {}
    for t in a.t:
        gen = torch.Generator().manual_seed(a.seed + t)
        noise = torch.randn(xl.shape, generator=gen)
        tt = torch.full((b,), t, dtype=torch.long)
        res = {}
        with torch.no_grad():
            for name, x0, e in (("lowg->phi", xl, phi), ("lowg->earth", xl, erth), ("earth->phi", xe, phi),
                                ("earth->earth", xe, erth)):
                xt = sched.add_noise(x0, noise, tt)
                pred = net(xt, tt, Condition(text=text, env=e, alpha=1.0))
                res[name] = round(apex(features_to_joints(pred * std + mean).numpy()), 3)
        out[t] = res
    print(json.dumps({"model": str(folder), "apex_gain_median_m": out}))
