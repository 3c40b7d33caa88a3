"""Spurious jumps in walks: 4 walking prompts x 16 samples (seed 3000+i, 120 frames, Earth, shipped sampling
settings); counts samples that jump by the checker's rule (flight >= 0.2 s, pelvis >= 15 cm).
Usage: python walk_probe.py MODEL..."""
import sys, time
import numpy as np, torch
from simdiff.eval.model_check.detect import jump_stats
from simdiff.model.generator import MotionGenerator
from simdiff.motion.features import features_to_joints

PROMPTS = ["a person walks forward", "a person is walking straight ahead",
           "a person turns around and walks back", "a person walks in a circle"]
torch.set_num_threads(1)
n = 16
for model in sys.argv[1:]:
    gen, start, rows = MotionGenerator.load(model), time.time(), []
    for i, p in enumerate(PROMPTS):
        out = gen.generate([p] * n, 120, seed=3000 + i, steps=50, guidance=2.5, foot_lock=1.0, alpha=0.5,
                           env=[-9.81, 0.0, 0.0])
        j = features_to_joints(out.features.double()).numpy()
        rows.append(sum(jump_stats(x)["jump"] for x in j))
    print(model, f"jumping {sum(rows)}/{n * len(PROMPTS)}", rows, f"{time.time() - start:.0f}s", flush=True)
