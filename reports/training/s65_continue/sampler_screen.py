"""Run/jog speed against the sampler (session 65, descriptive): python sampler_screen.py MODEL ALPHA.
"a person runs forward" / "a person jogs forward", 8 samples each, seeds 3100/3101 (as bb_screen.py), Earth, 120
frames, guidance 2.5, foot lock 1; DDIM 50 η 0 (shipped), DDIM 50 η 1, DDIM 100 η 0. Prints per-sample speeds."""
import statistics, sys, time
import torch
from simdiff.eval.model_check.detect import root_speed
from simdiff.model.generator import MotionGenerator
from simdiff.motion.features import features_to_joints
torch.set_num_threads(2)
model, alpha = sys.argv[1], float(sys.argv[2])
gen = MotionGenerator.load(model)
for steps, eta in ((50, 0.0), (50, 1.0), (100, 0.0)):
    t0, per = time.time(), {}
    for i, p in enumerate(["a person runs forward", "a person jogs forward"]):
        out = gen.generate([p] * 8, 120, seed=3100 + i, steps=steps, eta=eta, guidance=2.5, foot_lock=1.0, alpha=alpha,
                           env=[-9.81, 0.0, 0.0])
        per[p.split()[2]] = sorted(root_speed(x) for x in features_to_joints(out.features.double()).numpy())
    pooled = statistics.median(v for vs in per.values() for v in vs)
    print(f"{model.rstrip('/').split('/')[-1]} alpha {alpha} DDIM {steps} eta {eta}: pooled {pooled:.2f}; "
          + "; ".join(f"{k} " + " ".join(f"{v:.2f}" for v in vs) for k, vs in per.items()) + f" ({time.time() - t0:.0f} s)", flush=True)
