"""Guidance in a limited interval (session 62 screen): classifier-free guidance only at timesteps t <= T_HI (and >= T_LO),
the conditional network alone at the others (Kynkäänniemi et al. 2024: guidance at the noisiest steps pulls samples
towards a few typical ones). python interval_probe.py MODEL T_HI[,T_LO] ...: the check's 6 jump prompts x 8 (seeds
1000+i as ag_probe.py, 120 frames, Earth, shipped sampling settings); jumping counts per prompt.
As a library: `patch(t_hi, t_lo)` switches every GuidedDenoiser in this process."""
from __future__ import annotations

import json
import sys
import time
from pathlib import Path

import torch

from simdiff.diffusion import guidance as G
from simdiff.eval.model_check.config import JUMP_PROMPTS
from simdiff.eval.model_check.detect import jump_stats
from simdiff.model.generator import MotionGenerator
from simdiff.motion.features import features_to_joints

_plain = G.GuidedDenoiser._text_guided


def patch(t_hi: int, t_lo: int = 0) -> None:
    def text_guided(self, x, timesteps, cond):
        t = int(timesteps.max())
        if t > t_hi or t < t_lo:
            out = self.denoiser(x, timesteps, cond)
            return out, out
        return _plain(self, x, timesteps, cond)
    G.GuidedDenoiser._text_guided = text_guided


if __name__ == "__main__":
    torch.set_num_threads(2)
    model = sys.argv[1]
    s = json.loads((Path(model) / "sampling.json").read_text())
    gen = MotionGenerator.load(model)
    for spec in sys.argv[2:]:
        hi, lo = (list(map(int, spec.split(","))) + [0])[:2]
        patch(hi, lo)
        start, counts = time.time(), []
        for i, p in enumerate(JUMP_PROMPTS):
            out = gen.generate([p] * 8, 120, seed=1000 + i, steps=s["steps"], guidance=s["guidance"], alpha=s["alpha"],
                               foot_lock=s["foot_lock"], env=(-9.81, 0.0, 0.0))
            counts.append(sum(bool(jump_stats(features_to_joints(f.double()).numpy())["jump"]) for f in out.features))
        print(f"{model} guidance at t in [{lo}, {hi}]: jumps {sum(counts)}/48 {counts} {time.time() - start:.0f}s", flush=True)
