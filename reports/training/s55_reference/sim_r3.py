"""Measurement M1 (sim_r3_plan.txt): R@3 and FID of the val clips, their Earth replays and their g -1.6 replays.
usage: python sim_r3.py AUG CORPUS EVALUATOR... (AUG: simdiff data augment's output over the val split, paired with
one g -1.6 condition; CORPUS: its source). Prints one block per evaluator; writes nothing.
env LONG=1: also keep the replays of 200 frames or more (the loader's MDM rule drops them; under g -1.6 these are the
clips whose flights the retiming lengthened), scored on their first 196 frames like every other motion."""
from __future__ import annotations

import os
import sys

import numpy as np
import torch

from simdiff.data.augment.dataset import read_env_table
from simdiff.data.humanml3d import HumanML3D
from simdiff.eval.evaluator import OurEvaluator
from simdiff.eval.metrics import fid, matching_metrics

DRAWS, BATCH, MAX_T = 200, 32, 196


def triples(aug: str, corpus: str) -> list[tuple]:
    """(ground-truth item, Earth replay item, g -1.6 replay item, their three datasets) for every val item whose Earth and
    low-gravity replays were both kept (same source clip and captions)."""
    gt, sim, env = HumanML3D(corpus, "val"), HumanML3D(aug, "train"), read_env_table(aug)
    if os.environ.get("LONG"):
        import simdiff.data.humanml3d as H

        limit, H.MAX_CLIP_FRAMES = H.MAX_CLIP_FRAMES, 10 ** 9
        sim = HumanML3D(aug, "train")
        H.MAX_CLIP_FRAMES = limit
    replays: dict[tuple, dict[str, object]] = {}
    for it in sim.items:
        row = env[it.clip_id]
        kind = "earth" if abs(row["env"][0] + 9.81) < 1e-6 else "low"
        replays.setdefault((row.get("source", it.clip_id), tuple(c.text for c in it.captions)), {})[kind] = it
    out = []
    for it in gt.items:
        r = replays.get((it.clip_id, tuple(c.text for c in it.captions)), {})
        if "earth" in r and "low" in r:
            out.append((it, r["earth"], r["low"]))
    print(f"val items {len(gt.items)}; replays kept: {len(sim.items)} "
          f"(Earth {sum(abs(env[i.clip_id]['env'][0] + 9.81) < 1e-6 for i in sim.items)}); items with both: {len(out)}")
    return [(gt, sim, out)]


def embed(ev: OurEvaluator, ds: HumanML3D, items: list) -> np.ndarray:
    """(N, D) motion embeddings of ``items`` (first 196 frames each), in batches of 32."""
    rows = []
    for i in range(0, len(items), BATCH):
        chunk = [ds.load_motion(it)[:MAX_T] for it in items[i:i + BATCH]]
        lengths = [len(m) for m in chunk]
        x = np.zeros((len(chunk), max(lengths), chunk[0].shape[1]), dtype=np.float32)
        for j, m in enumerate(chunk):
            x[j, :len(m)] = m
        rows.append(ev.embed_motion(torch.from_numpy(x), torch.tensor(lengths)))
    return np.concatenate(rows)


def main() -> None:
    aug, corpus, evaluators = sys.argv[1], sys.argv[2], sys.argv[3:]
    (gt, sim, trip), = triples(aug, corpus)
    torch.set_num_threads(2)
    for path in evaluators:
        ev = OurEvaluator.load(path)
        emb = {"ground truth": embed(ev, gt, [t[0] for t in trip]), "Earth replay": embed(ev, sim, [t[1] for t in trip]),
               "g -1.6 replay": embed(ev, sim, [t[2] for t in trip])}
        r3 = {k: [] for k in emb}
        for seed in range(DRAWS):
            rng = np.random.default_rng(seed)
            order = rng.integers(len(trip), size=len(trip))  # a bootstrap resample of the items, in random order
            caps = [trip[i][0].captions[int(rng.integers(len(trip[i][0].captions)))].text for i in order]
            text = ev.embed_text(caps)
            for k, e in emb.items():
                r3[k].append(float(matching_metrics(text, e[order]).r_precision[2]))
        print(f"evaluator {path}: n {len(trip)} items; {DRAWS} bootstrap resamples of the items, one caption drawn per "
              f"item, batches of {BATCH}; 95 % percentile intervals")
        for k, e in emb.items():
            v = np.array(r3[k])
            lo, hi = np.percentile(v, [2.5, 97.5])
            print(f"  {k:14s} R@3 {v.mean():.3f} [{lo:.3f}, {hi:.3f}]"
                  + ("" if k == "ground truth" else f"; FID vs ground truth {fid(e, emb['ground truth']):.2f}"))
        for a, b in (("g -1.6 replay", "Earth replay"), ("Earth replay", "ground truth")):
            d = np.array(r3[a]) - np.array(r3[b])
            lo, hi = np.percentile(d, [2.5, 97.5])
            print(f"  {a} minus {b}, paired: {d.mean():+.3f} [{lo:+.3f}, {hi:+.3f}]")


if __name__ == "__main__":
    main()
