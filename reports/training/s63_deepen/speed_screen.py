"""Run and jog speed under classifier-free guidance w (session 63 screen, descriptive): python speed_screen.py
MODEL:W[,W...][:ALPHA] ... For each model and w (ALPHA: the adapter strength, default 0.5): "a person runs forward" and "a person jogs forward", 8 samples each (seed
3100 + prompt index, fresh), 120 frames, Earth, the model's other sampling settings (alpha 0.5, DDIM 50, foot lock 1);
prints per prompt the median mean-horizontal pelvis speed (the check's root_speed) and the pooled median, against
the corpus train runs' IQR [2.11, 2.96] m/s that stage B and the test check use."""
import statistics
import sys
import time

import torch

from simdiff.eval.model_check.detect import root_speed
from simdiff.model.generator import MotionGenerator
from simdiff.motion.features import features_to_joints

PROMPTS = ["a person runs forward", "a person jogs forward"]

if __name__ == "__main__":
    torch.set_num_threads(2)
    for spec in sys.argv[1:]:
        parts = spec.split(":")
        model, ws, alpha = parts[0], parts[1], float(parts[2]) if len(parts) > 2 else 0.5
        gen = MotionGenerator.load(model)
        for w in map(float, ws.split(",")):
            start, per = time.time(), {}
            for i, p in enumerate(PROMPTS):
                out = gen.generate([p] * 8, 120, seed=3100 + i, steps=50, guidance=w, foot_lock=1.0, alpha=alpha,
                                   env=[-9.81, 0.0, 0.0])
                j = features_to_joints(out.features.double()).numpy()
                per[p] = [root_speed(x) for x in j]
            pooled = statistics.median(v for vs in per.values() for v in vs)
            print(f"{model} w {w} alpha {alpha}: " + ", ".join(f"{p.split()[2]} {statistics.median(v):.2f}" for p, v in per.items())
                  + f", pooled {pooled:.2f} m/s ({time.time() - start:.0f} s)", flush=True)
