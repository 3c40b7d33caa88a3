import sys, numpy as np, torch
from simdiff.model.generator import MotionGenerator
from simdiff.motion.features import features_to_joints
torch.set_num_threads(2)
for model, se in [(m, float(s)) for m in sys.argv[1].split(",") for s in sys.argv[2].split(",")]:
    g = MotionGenerator.load(model)
    for p in ["a person runs forward", "a person jogs forward", "a person jumps forward"]:
        out = g.generate([p] * 8, 120, seed=0, sampler="ddim", steps=50, guidance=2.5, alpha=0.5, foot_lock=1.0,
                         env=[-1.6, 0, 0], env_guidance=se)
        j = features_to_joints(out.features.double()).numpy()
        ft = j[:, :, [7, 8, 10, 11], 1]
        frange = np.ptp(ft, axis=1).max(1)                       # (8,) largest foot-joint height range
        speed = np.linalg.norm(np.diff(j[:, :, 0, [0, 2]], axis=1), axis=-1).mean(1) * 20
        low = j[..., 1].min(-1).min(-1)
        print(model.split('/')[-1], se, p[9:], "float", int((low > 0.1).sum()), "foot range med %.2f min %.2f" % (np.median(frange), frange.min()),
              "static-feet(<0.05)", int((frange < 0.05).sum()), "speed med %.2f" % np.median(speed), flush=True)
