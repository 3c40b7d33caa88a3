"""Session 46's speed probe: median horizontal pelvis speed (m/s) of the checker's walk/run prompts at several
sample lengths (frames, 20 fps). N samples per prompt, seed 2000 + prompt index, Earth, alpha 0.5, the earlier checks'
sampler settings (DDIM 20, guidance 2.5, foot lock 1). A screen, not a claim.
Usage: python speed_probe.py MODEL_DIR 40,60,120 [N]
"""
import sys

import numpy as np
import torch

from simdiff.eval.model_check.config import SPEED_PROMPTS
from simdiff.eval.model_check.detect import root_speed
from simdiff.model.generator import MotionGenerator
from simdiff.motion.features import features_to_joints


def main() -> None:
    torch.set_num_threads(2)
    model = MotionGenerator.load(sys.argv[1])
    lengths = [int(x) for x in sys.argv[2].split(",")]
    n = int(sys.argv[3]) if len(sys.argv) > 3 else 8
    kw = dict(sampler="ddim", steps=20, eta=0.0, guidance=2.5, foot_lock=1.0)
    if model.is_simdiff:
        kw.update(alpha=0.5, env=[-9.81, 0.0, 0.0])
    for length in lengths:
        cells = []
        for kind, prompts in SPEED_PROMPTS.items():
            for i, prompt in enumerate(prompts):
                out = model.generate([prompt] * n, length, seed=2000 + i, **kw)
                joints = features_to_joints(out.features.double()).numpy()
                s = [root_speed(j) for j in joints]
                cells.append(f"{prompt!r} {np.median(s):.2f} [{np.percentile(s, 25):.2f}, {np.percentile(s, 75):.2f}]")
        print(f"length {length}:", " | ".join(cells), flush=True)


if __name__ == "__main__":
    main()
