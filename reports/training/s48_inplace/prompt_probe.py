"""Session 48's screen: given prompts x 8 samples (seed 7) at 60 and 120 frames, the shipped settings (DDIM 50,
guidance 2.5, alpha 0.5, s_e 2, foot cleanup 1, Earth); prints jumps (simdiff.eval.model_check.detect.jump_stats),
each sample's longest flight (s) and pelvis peak above its median height (m). A screen (one seed), not a claim.
Usage: python prompt_probe.py MODEL_DIR PROMPT [PROMPT ...]
"""
import sys

import numpy as np
import torch

from simdiff.eval.model_check.detect import jump_stats
from simdiff.model.generator import MotionGenerator
from simdiff.motion.features import features_to_joints


def main() -> None:
    torch.set_num_threads(2)
    gen = MotionGenerator.load(sys.argv[1])
    for prompt in sys.argv[2:]:
        for length in (60, 120):
            out = gen.generate([prompt] * 8, length, seed=7, sampler="ddim", steps=50, eta=0.0, guidance=2.5,
                               foot_lock=1.0, alpha=0.5, env=[-9.81, 0.0, 0.0], env_guidance=2.0)
            joints = features_to_joints(out.features.double()).numpy()
            stats = [jump_stats(j) for j in joints]
            peaks = [round(float(j[:, 0, 1].max() - np.median(j[:, 0, 1])), 2) for j in joints]
            print(f"{prompt!r} {length} frames: jumps {sum(s['jump'] for s in stats)}/8, flights "
                  f"{[round(s['flight_s'], 2) for s in stats]}, pelvis peaks {peaks}", flush=True)


if __name__ == "__main__":
    main()
