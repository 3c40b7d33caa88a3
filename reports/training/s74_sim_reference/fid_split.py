"""Session 74 (information after rule 88): where do the samples under g -1.6 sit between the Earth clip and the
simulator's low-g replay of the same val caption? For n ids of rule 87's reference corpus (seed 0), each MODEL samples
the id's first caption at the replay's length (<= 196 frames, multiple of 4) under g -1.6 with its sampling.json
(seed 0, batches of 32); evaluator 1 embeds sample, replay and Earth clip. Per id: distances d(sample, replay),
d(sample, Earth clip), d(Earth clip, replay) in the evaluator's motion space; medians for the retimed replays and the
rest, and the share of samples nearer their replay than their Earth clip; FID of the samples against the replays.
python fid_split.py REF_CORPUS EARTH_CORPUS EVALUATOR AUG MODEL... [--n 128]"""
from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
import torch
from clip_embed import MAX_FRAMES, embed_motions, first_caption, load_clip

from simdiff.eval.evaluator import OurEvaluator
from simdiff.eval.metrics import fid
from simdiff.model.generator import MotionGenerator

ap = argparse.ArgumentParser()
ap.add_argument("ref", type=Path)
ap.add_argument("earth", type=Path)
ap.add_argument("evaluator", type=Path)
ap.add_argument("aug", type=Path)
ap.add_argument("models", nargs="+")
ap.add_argument("--n", type=int, default=128)
a = ap.parse_args()
torch.set_num_threads(2)
ev = OurEvaluator.load(a.evaluator)
env = json.loads((a.aug / "env.json").read_text())
retimed = {v["source"] for v in env.values() if v["factor"] == "gravity" and v.get("retime_scale")}
pool = sorted((a.ref / "val.txt").read_text().split())
ids = sorted(np.random.default_rng(0).choice(pool, min(a.n, len(pool)), replace=False))


lens = [max(40, min(MAX_FRAMES, len(np.load(a.ref / "new_joint_vecs" / f"{k}.npy"))) // 4 * 4) for k in ids]
caps = [first_caption(a.ref, k) for k in ids]
rep = embed_motions(ev, np.stack([load_clip(a.ref, k, n)[0] for k, n in zip(ids, lens)]), lens)
ear = embed_motions(ev, np.stack([load_clip(a.earth, k, n)[0] for k, n in zip(ids, lens)]), lens)
is_re = np.array([k in retimed for k in ids])
d_er = np.linalg.norm(ear - rep, axis=1)
out = {"n": len(ids), "retimed": int(is_re.sum()), "fid_earth_vs_replays": fid(ear, rep),
       "median_d_earth_replay": {"retimed": float(np.median(d_er[is_re])), "rest": float(np.median(d_er[~is_re]))}}
for model in a.models:
    s = json.loads((Path(model) / "sampling.json").read_text())
    gen, feats = MotionGenerator.load(model), []
    for i in range(0, len(ids), 32):
        f = gen.generate(caps[i:i + 32], lens[i:i + 32], seed=i, steps=s["steps"], guidance=s["guidance"],
                         eta=s.get("eta", 0.0), alpha=s["alpha"], foot_lock=s["foot_lock"], env=[-1.6, 0.0, 0.0],
                         env_guidance=s["env_guidance"], anchor=s.get("anchor", "adapters"),
                         anchor_alpha=s.get("anchor_alpha", 0.0),
                         **({"edit_t": s["edit_t"]} if "edit_t" in s else {})).features.numpy()
        feats += [np.pad(x[:n], ((0, MAX_FRAMES - n), (0, 0))) for x, n in zip(f, lens[i:i + 32])]
    g = embed_motions(ev, np.stack(feats).astype(np.float32), lens)
    d_gr, d_ge = np.linalg.norm(g - rep, axis=1), np.linalg.norm(g - ear, axis=1)
    row = {"fid_vs_replays": fid(g, rep), "fid_vs_earth": fid(g, ear)}
    for name, m in (("retimed", is_re), ("rest", ~is_re)):
        row[name] = {"median_d_sample_replay": float(np.median(d_gr[m])),
                     "median_d_sample_earth": float(np.median(d_ge[m])),
                     "nearer_replay": f"{int((d_gr[m] < d_ge[m]).sum())}/{int(m.sum())}"}
    out[Path(model).name] = row
    print(json.dumps({Path(model).name: row}), flush=True)
print(json.dumps(out))
