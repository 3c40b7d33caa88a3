"""Autoguidance screen: f = good + lam*(good - bad) as the network, then the usual CFG. Jump probe (6 prompts x N,
seed 1000+i, 120 frames, Earth, alpha 0.5, DDIM 50, cleanup 1.0).
Usage: python ag_probe.py GOOD BAD '[{"lam":0}, {"lam":1, "guidance":1.5}]' [N]"""
import json, sys, time
import numpy as np, torch
from torch import nn
from simdiff.eval.model_check.config import JUMP_PROMPTS
from simdiff.eval.model_check.detect import jump_stats
from simdiff.model.generator import MotionGenerator
from simdiff.model.checkpoint import load_pretrained
from simdiff.motion.features import features_to_joints


class Extrap(nn.Module):
    def __init__(self, good, bad, lam):
        super().__init__(); self.good, self.bad, self.lam = good, bad, lam
    def forward(self, x, t, cond):
        g = self.good(x, t, cond)
        if self.lam == 0:
            return g
        return g + self.lam * (g - self.bad(x, t, cond))


def main():
    torch.set_num_threads(2)
    gen = MotionGenerator.load(sys.argv[1])
    bad, _, _ = load_pretrained(sys.argv[2])
    bad.eval().requires_grad_(False)
    good = gen.network
    n = int(sys.argv[4]) if len(sys.argv) > 4 else 8
    for s in json.loads(sys.argv[3]):
        gen.network = Extrap(good, bad, s.get("lam", 0.0))
        start, rows = time.time(), []
        for i, prompt in enumerate(JUMP_PROMPTS):
            out = gen.generate([prompt] * n, 120, seed=1000 + i, sampler="ddim", steps=50, guidance=s.get("guidance", 2.5),
                               foot_lock=1.0, alpha=0.5, env=[-9.81, 0.0, 0.0])
            joints = features_to_joints(out.features.double()).numpy()
            st = [jump_stats(j) for j in joints]
            rows.append((sum(x["jump"] for x in st), np.median([x["flight_s"] for x in st]),
                         np.median([j[:, 0, 1].max() - np.median(j[:, 0, 1]) for j in joints])))
        print(json.dumps(s), f"jumps {sum(r[0] for r in rows)}/{n * len(JUMP_PROMPTS)}",
              " ".join(f"{a}|{b:.2f}|{c:.2f}" for a, b, c in rows), f"{time.time() - start:.0f}s", flush=True)

main()
