"""Session 50 probe: under g -1.6, how many samples never touch the floor (lowest foot joint > 0.10 m in every frame)
and the median airborne fraction, per s_e. 10 prompts (6 jump + 4 walk/run) x 8 samples, seed 0, shipped settings."""
import sys, json
import numpy as np, torch
from simdiff.eval.model_check.config import JUMP_PROMPTS, SPEED_PROMPTS
from simdiff.model.generator import MotionGenerator
from simdiff.motion.features import features_to_joints
torch.set_num_threads(2)
g = MotionGenerator.load("simdiff/assets/default_model")
prompts = list(JUMP_PROMPTS) + [p for v in SPEED_PROMPTS.values() for p in v]
env = [float(v) for v in sys.argv[1].split(",")]
for se in [float(s) for s in sys.argv[2].split(",")]:
    rows = []
    for i, p in enumerate(prompts):
        out = g.generate([p] * 8, 120, seed=i, sampler="ddim", steps=50, guidance=2.5, alpha=0.5, foot_lock=1.0,
                         env=env, env_guidance=se)
        j = features_to_joints(out.features.double()).numpy()
        low = j[:, :, [7, 8, 10, 11], 1].min(2)  # (8, T) lowest foot joint height, m
        rows.append((p, int((low.min(1) > 0.10).sum()), float(np.median((low > 0.10).mean(1))), float(np.median(low.min(1)))))
    print(json.dumps({"env": env, "s_e": se, "never_touch": sum(r[1] for r in rows), "of": 8 * len(prompts),
                      "per_prompt": [(r[0][9:], r[1], round(r[2], 2), round(r[3], 2)) for r in rows]}), flush=True)
