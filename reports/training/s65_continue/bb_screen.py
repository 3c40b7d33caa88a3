"""Backbone screen (session 65, descriptive): run/jog speed and jump rate of a model at adapter strength ALPHA.
python bb_screen.py MODEL[:ALPHA] ...  Speed: "runs/jogs forward", 8 samples each, seeds 3100/3101 (as s63/s64).
Jumps: "jumps forward", "jumps in place", "hops on one leg", 8 samples each, seeds 3200+; jump_stats' verdict
(flight >= 0.2 s, pelvis rise >= 15 cm). Earth, 120 frames, guidance 2.5, DDIM 50, foot lock 1."""
import statistics, sys, time
import torch
from simdiff.eval.model_check.detect import jump_stats, root_speed
from simdiff.model.generator import MotionGenerator
from simdiff.motion.features import features_to_joints
SPEED = ["a person runs forward", "a person jogs forward"]
JUMPS = ["a person jumps forward", "a person jumps in place", "a person hops on one leg"]
torch.set_num_threads(2)
for spec in sys.argv[1:]:
    model, alpha = (spec.rsplit(":", 1)[0], float(spec.rsplit(":", 1)[1])) if ":" in spec else (spec, 0.0)
    gen = MotionGenerator.load(model)
    kw = dict(steps=50, guidance=2.5, foot_lock=1.0)
    if gen.is_simdiff:
        kw.update(alpha=alpha, env=[-9.81, 0.0, 0.0])
    t0, per, jumps = time.time(), {}, {}
    for i, p in enumerate(SPEED):
        j = features_to_joints(gen.generate([p] * 8, 120, seed=3100 + i, **kw).features.double()).numpy()
        per[p] = [root_speed(x) for x in j]
    for i, p in enumerate(JUMPS):
        j = features_to_joints(gen.generate([p] * 8, 120, seed=3200 + i, **kw).features.double()).numpy()
        st = [jump_stats(x) for x in j]
        jumps[p] = (sum(s["jump"] for s in st), statistics.median(s["rise_m"] for s in st))
    pooled = statistics.median(v for vs in per.values() for v in vs)
    print(f"{model} alpha {alpha}: " + ", ".join(f"{p.split()[2]} {statistics.median(v):.2f}" for p, v in per.items())
          + f", pooled {pooled:.2f} m/s; jumps " + ", ".join(f"{p.split(' ', 3)[3]} {n}/8" for p, (n, r) in jumps.items())
          + f" = {sum(n for n, _ in jumps.values())}/24 ({time.time() - t0:.0f} s)", flush=True)
