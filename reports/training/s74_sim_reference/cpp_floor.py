"""Session 74 (information on rule 87's C''): what its FID bar asks. Evaluator 1 on rule 87's reference corpus (the
simulator's low-g replays of the val clips) and on corpus3's Earth val clips of the same ids: for 5 draws (seeds 0-4)
of n ids, FID of the replays against an independent second draw from the same pool (the model check's floor: the
draws overlap), against the disjoint rest of the pool, and FID of the *Earth* clips of the first draw against the
replays' second draw (what a model that ignores gravity would score); R@3 (batches of 32) of replays and Earth clips
with their own first captions. Motions cut to 196 frames (the evaluator's).
python cpp_floor.py REF_CORPUS EARTH_CORPUS EVALUATOR [--n 128]"""
from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
import torch
from clip_embed import embed_motions, embed_texts, first_caption, load_clip

from simdiff.eval.evaluator import OurEvaluator
from simdiff.eval.metrics import fid, matching_metrics

ap = argparse.ArgumentParser()
ap.add_argument("ref", type=Path)
ap.add_argument("earth", type=Path)
ap.add_argument("evaluator", type=Path)
ap.add_argument("--n", type=int, default=128)
a = ap.parse_args()
torch.set_num_threads(2)
ev = OurEvaluator.load(a.evaluator)


def embed(root: Path, keys: list[str]) -> tuple[np.ndarray, np.ndarray]:
    """(motion embeddings, caption embeddings) of keys, motions cut/padded to 196 frames."""
    clips = [load_clip(root, k) for k in keys]
    lens = [max(4, n // 4 * 4) for _, n in clips]
    captions = [first_caption(root, k) for k in keys]
    return embed_motions(ev, np.stack([x for x, _ in clips]), lens), embed_texts(ev, captions)


pool = sorted((a.ref / "val.txt").read_text().split())
rep_m, rep_t = embed(a.ref, pool)
ear_m, ear_t = embed(a.earth, pool)
rows = []
for seed in range(5):
    rng = np.random.default_rng(seed)
    d1, d2 = rng.choice(len(pool), a.n, replace=False), rng.choice(len(pool), a.n, replace=False)
    rest = np.setdiff1d(np.arange(len(pool)), d1)
    rows.append({"seed": seed, "overlap": len(np.intersect1d(d1, d2)),
                 "fid_replays_vs_resample": fid(rep_m[d1], rep_m[d2]),
                 "fid_replays_vs_disjoint_rest": fid(rep_m[d1], rep_m[rest]),
                 "fid_earth_vs_replays_resample": fid(ear_m[d1], rep_m[d2]),
                 "r3_replays": float(matching_metrics(rep_t[d1], rep_m[d1]).r_precision[2]),
                 "r3_earth": float(matching_metrics(ear_t[d1], ear_m[d1]).r_precision[2])})
keys = [k for k in rows[0] if k != "seed"]
print(json.dumps({"pool": len(pool), "n": a.n, "mean": {k: float(np.mean([r[k] for r in rows])) for k in keys},
                  "draws": rows}))
