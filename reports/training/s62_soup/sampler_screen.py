"""Is the missing jump in place a sampling setting? (session 62) python sampler_screen.py MODEL
The check's "jumps up in place" / "jumps up and down" / "long jump" / "jumps forward" prompts x 8 (seed 0, Earth, α 0.5,
foot cleanup 1, DDIM 50): DDIM η 0 / 0.5 / 1 at guidance 2.5 and 120 frames; guidance 6; 40 and 80 frames."""
import sys

import torch

from simdiff.eval.model_check.detect import jump_stats
from simdiff.model.generator import MotionGenerator
from simdiff.motion.features import features_to_joints

PROMPTS = ["a person jumps up in place", "a person jumps up and down", "a person does a long jump", "a person jumps forward"]
torch.set_num_threads(2)
gen = MotionGenerator.load(sys.argv[1])
for eta, guidance, frames in [(0.0, 2.5, 120), (0.5, 2.5, 120), (1.0, 2.5, 120), (0.0, 6.0, 120), (0.0, 2.5, 40),
                              (0.0, 2.5, 80)]:
    counts = []
    for p in PROMPTS:
        out = gen.generate([p] * 8, frames, env=(-9.81, 0, 0), alpha=0.5, steps=50, eta=eta, guidance=guidance, seed=0,
                           foot_lock=1.0)
        counts.append(sum(bool(jump_stats(features_to_joints(f.numpy()))["jump"]) for f in out.features))
    print(f"eta {eta} guidance {guidance} frames {frames}: jumping of 8 per prompt {dict(zip(PROMPTS, counts))}", flush=True)
