"""Does the network keep a jump it is shown? (session 62) python retention.py MODEL...

Each val clip below (its first 120 frames, normalised) is noised to DDIM-50 timestep t with 8 noise draws (seed 0) and
denoised from there with the caption given (Earth, α 0.5, guidance 2.5, no foot cleanup); counts the samples that
still jump by the model check's rule (flight >= 0.2 s, pelvis >= 15 cm up). t 980 is pure noise: the motion is the
network's own. A network that keeps the jump at moderate t but not from noise can draw it but does not choose it; one
that loses it at moderate t pulls that motion towards another."""
from __future__ import annotations

import sys
import time

import numpy as np
import torch

from simdiff.diffusion.sampling import make_scheduler, sample
from simdiff.eval.model_check.detect import jump_stats
from simdiff.model.condition import Condition
from simdiff.model.generator import MotionGenerator
from simdiff.motion.features import features_to_joints

CORPUS = "/work/scratch/s39/corpus3"
CLIPS = [("13_40_00", "a person jumps up in place"), ("13_42_00", "a person jumps up in place"),
         ("M13_40_00", "a person jumps up in place"), ("M13_42_00", "a person jumps up in place"),
         ("hdm_bd_hopBothLegs1hops_003_00", "a person hops forward on both feet")]
TS = (400, 600, 800, 999)
N = 8


def retained(gen: MotionGenerator, clip: str, caption: str) -> list[int]:
    f = torch.tensor(np.load(f"{CORPUS}/new_joint_vecs/{clip}.npy"), dtype=torch.float32)[:120]
    x0 = ((f - gen.mean.cpu()) / gen.std.cpu())[None].repeat(N, 1, 1)
    cond = Condition(text=gen.encode_text([caption] * N), frame_mask=torch.ones(N, len(f), dtype=torch.bool),
                     alpha=0.5, env=torch.tensor([[-9.81, 0.0, 0.0]]).expand(N, 3))
    counts = []
    for ts in TS:
        sch = make_scheduler("ddim", 50)
        rng = torch.Generator().manual_seed(0)
        noise = torch.randn(x0.shape, generator=rng)
        sch.timesteps = sch.timesteps[sch.timesteps <= ts]
        xt = sch.add_noise(x0, noise, torch.full((N,), int(sch.timesteps[0])))
        x = sample(gen.network, sch, cond, len(f), x_init=xt, guidance=2.5, generator=rng)
        feats = (x * gen.std + gen.mean).numpy()
        counts.append(sum(bool(jump_stats(features_to_joints(a))["jump"]) for a in feats))
    return counts


if __name__ == "__main__":
    torch.set_num_threads(2)
    for model in sys.argv[1:]:
        start = time.time()
        gen = MotionGenerator.load(model)
        rows = {clip: retained(gen, clip, cap) for clip, cap in CLIPS}
        inplace = [sum(r[i] for c, r in rows.items() if c != CLIPS[-1][0]) for i in range(len(TS))]
        print(model, "in place (4 clips x 8) kept at t", dict(zip(TS, inplace)), "| forward hop (8) kept",
              dict(zip(TS, rows[CLIPS[-1][0]])), f"{time.time() - start:.0f}s", flush=True)
