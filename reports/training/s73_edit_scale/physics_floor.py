"""Session 73: what stage C' (R@3 and FID of samples under g -1.6 against the Earth ground truth) asks of the
simulator's own answer. Evaluator 1 on aug_lowloc's replays (walk and run clips): its Earth replays and its low-gravity
replays (g in [-2.5, -1.2], retimed), each against corpus3's val ground truth (FID) and its own captions (R@3, batches of
32), n items drawn alike (seed 0), lengths cut to 196 frames (the evaluator's). Since those clips are walks and runs
only, their FID against val's mixed content is large; the FID of the low-g replays against the Earth replays (same
content) is the shift the simulator's physics alone makes, beside the Earth replays' own two-halves FID.
python physics_floor.py AUG CORPUS EVALUATOR [--n 256]"""
from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
import torch

from simdiff.eval.evaluator import OurEvaluator
from simdiff.eval.metrics import fid, matching_metrics

ap = argparse.ArgumentParser()
ap.add_argument("aug", type=Path)
ap.add_argument("corpus", type=Path)
ap.add_argument("evaluator", type=Path)
ap.add_argument("--n", type=int, default=256)
a = ap.parse_args()
torch.set_num_threads(2)
ev = OurEvaluator.load(a.evaluator)


def load(root: Path, keys: list[str]) -> tuple[np.ndarray, list[str], list[int]]:
    feats, caps, lens = [], [], []
    for k in keys:
        x = np.load(root / "new_joint_vecs" / f"{k}.npy")[:196].astype(np.float32)
        feats.append(np.pad(x, ((0, 196 - len(x)), (0, 0))))
        lens.append(len(x) // 4 * 4)
        caps.append((root / "texts" / f"{k}.txt").read_text().splitlines()[0].split("#")[0])
    return np.stack(feats), caps, lens


def embed(root: Path, keys: list[str]) -> tuple[np.ndarray, np.ndarray]:
    x, caps, lens = load(root, keys)
    m = np.concatenate([ev.embed_motion(torch.from_numpy(x[i:i + 64]), lens[i:i + 64]) for i in range(0, len(x), 64)])
    t = np.concatenate([ev.embed_text(caps[i:i + 64]) for i in range(0, len(caps), 64)])
    return m, t


rng = np.random.default_rng(0)
emb: dict[str, np.ndarray] = {}
env = json.loads((a.aug / "env.json").read_text())
val = [k for k in (a.corpus / "val.txt").read_text().split() if (a.corpus / "new_joint_vecs" / f"{k}.npy").exists()]
gt_m, gt_t = embed(a.corpus, sorted(rng.choice(val, min(a.n, len(val)), replace=False)))
out = {"n": a.n, "gt_val": {"r_precision_top3": float(matching_metrics(gt_t, gt_m).r_precision[2])}}
sources = {v["source"] for k, v in env.items() if v["factor"] == "earth"}
for name, pick in (("earth_replays", lambda v: v["factor"] == "earth"),
                   ("low_g_replays_same_sources", lambda v: v["factor"] != "earth" and v["source"] in sources),
                   ("low_g_replays", lambda v: v["factor"] != "earth")):
    keys = sorted(k for k, v in env.items() if pick(v))
    keys = sorted(rng.choice(keys, min(a.n, len(keys)), replace=False))
    m, t = embed(a.aug, keys)
    emb[name] = m
    out[name] = {"items": len(keys), "fid_vs_val_gt": fid(m, gt_m),
                 "r_precision_top3": float(matching_metrics(t, m).r_precision[2])}
half = len(emb["earth_replays"]) // 2
out["fid_earth_replays_half_vs_half"] = fid(emb["earth_replays"][:half], emb["earth_replays"][half:])
out["fid_low_g_vs_earth_replays"] = fid(emb["low_g_replays"], emb["earth_replays"])
out["fid_low_g_half_vs_earth_half"] = fid(emb["low_g_replays"][:half], emb["earth_replays"][half:])
print(json.dumps(out))
