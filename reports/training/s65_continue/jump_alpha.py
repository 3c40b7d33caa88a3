"""The model check's jump/hop prompts at adapter strength 0 and 0.5 (session 65, descriptive): 8 samples per prompt
(seed 3300 + prompt index), Earth, 120 frames, guidance 2.5, DDIM 50, foot lock 1; jump_stats' verdict."""
import sys, time
import torch
from simdiff.eval.model_check.config import JUMP_PROMPTS
from simdiff.eval.model_check.detect import jump_stats
from simdiff.model.generator import MotionGenerator
from simdiff.motion.features import features_to_joints
torch.set_num_threads(2)
for model in sys.argv[1:]:
    gen = MotionGenerator.load(model)
    for alpha in (0.0, 0.5):
        t0, per = time.time(), []
        for i, p in enumerate(JUMP_PROMPTS):
            j = features_to_joints(gen.generate([p] * 8, 120, seed=3300 + i, steps=50, guidance=2.5, foot_lock=1.0,
                                                alpha=alpha, env=[-9.81, 0.0, 0.0]).features.double()).numpy()
            per.append(sum(bool(jump_stats(x)["jump"]) for x in j))
        print(f"{model.rstrip('/').split('/')[-1]} alpha {alpha}: {sum(per)} of {8 * len(per)} jump; per prompt {per} "
              f"({time.time() - t0:.0f} s)", flush=True)
