"""Spurious jumps: 6 prompts that ask for no jump x N samples (seed 2000+i, 120 frames, Earth, shipped sampling
settings); counts samples that jump by the checker's rule (flight >= 0.2 s, pelvis >= 15 cm).
Usage: python nonjump_probe.py MODEL...
(session 54: env PROBE_ANCHOR, the guidance anchor, default adapters; PROBE_ALPHA, the adapter strength, default 0.5;
session 55: PROBE_ANCHOR_ALPHA, the anchor's adapter strength, default 0; session 76: PROBE_W, the guidance, default 2.5)"""
import os
import sys
import time

import torch

from simdiff.eval.model_check.detect import jump_stats
from simdiff.model.generator import MotionGenerator
from simdiff.motion.features import features_to_joints

PROMPTS = ["a person walks forward", "a person waves with the right hand", "a person sits down on a chair",
           "a person turns around and walks back", "a person kicks with the right leg", "a person dances"]


def probe(models: list[str], prompts: list[str], n: int, seed0: int) -> None:
    """Print, per model, how many of n samples per prompt (seed seed0 + prompt index) jump."""
    torch.set_num_threads(1)
    for model in models:
        gen, start, rows = MotionGenerator.load(model), time.time(), []
        for i, p in enumerate(prompts):
            out = gen.generate([p] * n, 120, seed=seed0 + i, steps=50, guidance=float(os.environ.get("PROBE_W", "2.5")), foot_lock=1.0,
                               alpha=float(os.environ.get("PROBE_ALPHA", "0.5")), env=[-9.81, 0.0, 0.0],
                               anchor=os.environ.get("PROBE_ANCHOR", "adapters"),
                               anchor_alpha=float(os.environ.get("PROBE_ANCHOR_ALPHA", "0")),
                               ballistic=float(os.environ.get("BALLISTIC") or 0))  # session 67
            j = features_to_joints(out.features.double()).numpy()
            rows.append(sum(jump_stats(x)["jump"] for x in j))
        print(model, f"jumping {sum(rows)}/{n * len(prompts)}", rows, f"{time.time() - start:.0f}s", flush=True)


if __name__ == "__main__":
    probe(sys.argv[1:], PROMPTS, 8, 2000)
