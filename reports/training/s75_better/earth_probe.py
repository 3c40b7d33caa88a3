"""Earth probe at alpha 0 (the backbone alone, X88's Earth sampling): how many samples jump, per prompt.
python earth_probe.py jumps|walks MODEL...   (env ETA: DDIM eta, default 1; N: samples per prompt, default 16)
jumps: the model check's 6 jump prompts, seed 1000+i; walks: walk_probe.py's 4 walking prompts, seed 3000+i
(120 frames, DDIM 50, guidance 2.5, foot lock 1, Earth)."""
from __future__ import annotations

import os
import sys
import time

import numpy as np
import torch

from simdiff.eval.model_check.config import JUMP_PROMPTS
from simdiff.eval.model_check.detect import jump_stats
from simdiff.model.generator import MotionGenerator
from simdiff.motion.features import features_to_joints

WALKS = ("a person walks forward", "a person is walking straight ahead",
         "a person turns around and walks back", "a person walks in a circle")


def main(kind: str, models: list[str]) -> None:
    torch.set_num_threads(2)
    prompts, seed0 = {"jumps": (JUMP_PROMPTS, 1000), "walks": (WALKS, 3000)}[kind]
    n, eta = int(os.environ.get("N", "16")), float(os.environ.get("ETA", "1"))
    for model in models:
        gen, start, rows = MotionGenerator.load(model), time.time(), []
        for i, p in enumerate(prompts):
            out = gen.generate([p] * n, 120, seed=seed0 + i, sampler="ddim", steps=50, guidance=2.5, foot_lock=1.0,
                               alpha=0.0, eta=eta, env=[-9.81, 0.0, 0.0])
            st = [jump_stats(j) for j in features_to_joints(out.features.double()).numpy()]
            rows.append((sum(bool(s["jump"]) for s in st), float(np.median([s["flight_s"] for s in st]))))
        print(kind, model, f"eta {eta}", f"jumping {sum(r[0] for r in rows)}/{n * len(prompts)}",
              " ".join(f"{k}|{f:.2f}" for k, f in rows), f"{time.time() - start:.0f}s", flush=True)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2:])
