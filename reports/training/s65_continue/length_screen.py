"""Walk/run speed against sample length (session 65, descriptive): the model check's speed prompts, 8 samples each
(seeds 3100 + prompt index), Earth, the model's sampling.json (alpha 0.5, w 2.5, DDIM 50, foot lock 1), lengths
60 and 120 frames; medians per motion type against corpus3's length-matched train clips (model check rule)."""
import statistics, sys, time
import torch
from simdiff.eval.model_check.config import SPEED_PROMPTS
from simdiff.eval.model_check.detect import root_speed
from simdiff.model.generator import MotionGenerator
from simdiff.motion.features import features_to_joints
torch.set_num_threads(2)
for model in sys.argv[1:]:
    gen = MotionGenerator.load(model)
    for n in (60, 120):
        t0, line = time.time(), []
        for kind, prompts in SPEED_PROMPTS.items():
            v = []
            for i, p in enumerate(prompts):
                out = gen.generate([p] * 8, n, seed=3100 + i, steps=50, guidance=2.5, foot_lock=1.0, alpha=0.5, env=[-9.81, 0.0, 0.0])
                v += [root_speed(x) for x in features_to_joints(out.features.double()).numpy()]
            line.append(f"{kind} {statistics.median(v):.2f}")
        print(f"{model.rstrip('/').split('/')[-1]} length {n}: " + ", ".join(line) + f" ({time.time()-t0:.0f} s)", flush=True)
