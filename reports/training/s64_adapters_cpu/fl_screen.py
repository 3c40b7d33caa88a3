"""Run/jog speed with and without foot lock (descriptive): same draws as speed_screen.py."""
import statistics, sys, time
import torch
from simdiff.eval.model_check.detect import root_speed
from simdiff.model.generator import MotionGenerator
from simdiff.motion.features import features_to_joints
PROMPTS = ["a person runs forward", "a person jogs forward"]
torch.set_num_threads(2)
for spec in sys.argv[1:]:
    model, alpha = spec.split(":")[0], float(spec.split(":")[1]) if ":" in spec else 0.5
    gen = MotionGenerator.load(model)
    for fl in (0.0, 1.0):
        t0, per = time.time(), {}
        for i, p in enumerate(PROMPTS):
            out = gen.generate([p] * 8, 120, seed=3100 + i, steps=50, guidance=2.5, foot_lock=fl, alpha=alpha, env=[-9.81, 0.0, 0.0])
            j = features_to_joints(out.features.double()).numpy()
            per[p] = [root_speed(x) for x in j]
        pooled = statistics.median(v for vs in per.values() for v in vs)
        print(f"{model} alpha {alpha} foot_lock {fl}: " + ", ".join(f"{p.split()[2]} {statistics.median(v):.2f}" for p, v in per.items()) + f", pooled {pooled:.2f} m/s ({time.time()-t0:.0f} s)", flush=True)
