"""Speed profile (m/s per 1 s window) of 8 jog samples, seed 3101, Earth, 120 frames (descriptive)."""
import sys
import numpy as np, torch
from simdiff.model.generator import MotionGenerator
from simdiff.motion.features import features_to_joints
torch.set_num_threads(2)
for model in sys.argv[1:]:
    gen = MotionGenerator.load(model)
    out = gen.generate(["a person jogs forward"] * 8, 120, seed=3101, steps=50, guidance=2.5, foot_lock=1.0, alpha=0.5, env=[-9.81, 0.0, 0.0])
    j = features_to_joints(out.features.double()).numpy()
    v = np.linalg.norm(np.diff(j[:, :, 0, [0, 2]], axis=1), axis=-1) * 20  # (8, 119) m/s
    w = v[:, :114].reshape(8, 6, 19).mean(-1)
    print(model.split("/")[-1], "per-second median:", np.round(np.median(w, 0), 2), "per-sample mean:", np.round(v.mean(1), 2))
