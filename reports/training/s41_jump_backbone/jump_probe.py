"""Session 41's quick jump probe: the checker's 6 jump/hop prompts x N samples (seed 1000 + prompt index, 120 frames)
under several sampler settings (a setting's "length" changes the frames); prints, per setting, how many samples jump (flight >= 0.2 s and pelvis >= 15 cm up,
simdiff.eval.model_check.detect.jump_stats) and per prompt "jumping|median flight s|median pelvis range m".
A screen (one seed, 8 samples per prompt), not a claim. SimDiff models run at Earth, alpha 0.5.
Usage: python jump_probe.py MODEL_DIR '[{}, {"eta": 1.0}, {"steps": 50}, {"guidance": 5.0}, {"foot_lock": 0.0}]' [N]
"""
import json
import sys
import time

import numpy as np
import torch

from simdiff.eval.model_check.config import JUMP_PROMPTS
from simdiff.eval.model_check.detect import jump_stats
from simdiff.model.generator import MotionGenerator
from simdiff.motion.features import features_to_joints


def main() -> None:
    torch.set_num_threads(2)
    gen_model = MotionGenerator.load(sys.argv[1])
    settings = json.loads(sys.argv[2])
    n = int(sys.argv[3]) if len(sys.argv) > 3 else 8
    for s in settings:
        start, rows = time.time(), []
        for i, prompt in enumerate(JUMP_PROMPTS):
            kw = dict(sampler=s.get("sampler", "ddim"), steps=s.get("steps", 20), eta=s.get("eta", 0.0),
                      guidance=s.get("guidance", 2.5), foot_lock=s.get("foot_lock", 1.0))
            if gen_model.is_simdiff:
                kw.update(alpha=0.5, env=[-9.81, 0.0, 0.0])
            out = gen_model.generate([prompt] * n, s.get("length", 120), seed=1000 + i, **kw)
            joints = features_to_joints(out.features.double()).numpy()
            stats = [jump_stats(j) for j in joints]
            rows.append((sum(x["jump"] for x in stats), np.median([x["flight_s"] for x in stats]),
                         np.median([j[:, 0, 1].max() - np.median(j[:, 0, 1]) for j in joints])))
        total = sum(r[0] for r in rows)
        print(json.dumps(s), f"jumps {total}/{n * len(JUMP_PROMPTS)}",
              " ".join(f"{a}|{b:.2f}|{c:.2f}" for a, b, c in rows), f"{time.time() - start:.0f}s", flush=True)


if __name__ == "__main__":
    main()
