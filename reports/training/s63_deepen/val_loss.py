"""Held-out denoising error of backbones, paired: python val_loss.py CORPUS NAME=MODEL [NAME=MODEL ...] [--split val].

Every clip of the split (one caption, one crop of <= 120 frames as in training, drawn with seed 0) is noised at
t in {50, 200, 400, 600, 800, 950} with two fixed noise draws (the same for every model) and each model's backbone
(text kept, no φ) predicts x0; the figure is the masked x0 MSE in normalised features, the training loss's main
term. Reported per t and over all t, for all clips and for jump/hop/leap captions, with the paired difference of
each model against the first (Student-t 95 % over clips). Decides nothing (session 63: descriptive)."""
from __future__ import annotations

import argparse
import json
import re

import numpy as np
import torch

from simdiff.data.humanml3d import HumanML3D, collate
from simdiff.diffusion.sampling import make_scheduler
from simdiff.eval.stats import t_interval
from simdiff.model.checkpoint import load_pretrained
from simdiff.model.condition import Condition
from simdiff.text.base import load_text_encoder

TS = (50, 200, 400, 600, 800, 950)
JUMP = re.compile(r"\b(jump|jumps|jumping|hop|hops|hopping|leap|leaps|leaping)\b", re.IGNORECASE)


@torch.no_grad()
def errors(net, batch, text, scheduler, draws: int = 2) -> np.ndarray:
    """(items, len(TS)) x0 MSE averaged over ``draws`` noise draws (seeded by t and draw, batch-independent)."""
    x0, mask = batch["motion"], batch["mask"]
    cond = Condition(text=text, frame_mask=mask)
    m = mask.float()[..., None]
    out = np.zeros((len(x0), len(TS)))
    for j, t in enumerate(TS):
        for d in range(draws):
            noise = torch.stack([torch.randn(x0.shape[1:], generator=torch.Generator().manual_seed(hash((i, t, d)) % 2**31))
                                 for i in batch["index"]])
            tt = torch.full((len(x0),), t, dtype=torch.long)
            pred = net(scheduler.add_noise(x0, noise, tt), tt, cond)
            out[:, j] += (((pred - x0) ** 2 * m).sum((1, 2)) / (m.sum((1, 2)) * x0.shape[-1])).numpy() / draws
    return out


def main() -> None:
    p = argparse.ArgumentParser()
    p.add_argument("corpus")
    p.add_argument("models", nargs="+", help="NAME=MODEL_FOLDER; the first is the reference")
    p.add_argument("--split", default="val")
    a = p.parse_args()
    torch.manual_seed(0)
    ds = HumanML3D(a.corpus, a.split, max_frames=120, seed=0)
    rng = np.random.default_rng(0)
    items = [dict(ds.get(i, rng), index=i) for i in range(len(ds))]
    enc = load_text_encoder("minilm")
    scheduler = make_scheduler("ddpm")
    jump = np.array([bool(JUMP.search(it["caption"])) for it in items])
    res = {}
    for spec in a.models:
        name, folder = spec.split("=", 1)
        net, _, extra = load_pretrained(folder)
        net.eval()
        assert torch.allclose(extra["normalizer.mean"], torch.as_tensor(ds.normalizer.mean, dtype=torch.float32)), name
        errs = []
        for s in range(0, len(items), 64):
            chunk = items[s:s + 64]
            batch = collate(chunk)
            batch["index"] = [c["index"] for c in chunk]
            errs.append(errors(net, batch, enc.encode(batch["captions"]), scheduler))
        res[name] = np.concatenate(errs)
    ref = a.models[0].split("=", 1)[0]
    summary = {"split": a.split, "n": len(items), "n_jump": int(jump.sum()), "t": list(TS), "models": {}}
    for name, e in res.items():
        row = {}
        for label, sel in (("all", slice(None)), ("jump", jump)):
            per_t = e[sel].mean(0)
            entry = {"per_t": [round(float(v), 4) for v in per_t], "mean": round(float(e[sel].mean()), 4)}
            if name != ref:
                diff = e[sel].mean(1) - res[ref][sel].mean(1)
                m, h = t_interval(list(diff))
                entry["paired_vs_" + ref] = [round(m, 4), round(h, 4)]
                entry["paired_per_t"] = [round(float(v), 4) for v in (e[sel] - res[ref][sel]).mean(0)]
            row[label] = entry
        summary["models"][name] = row
        print(name, json.dumps(row))
    print(json.dumps(summary))


if __name__ == "__main__":
    main()
