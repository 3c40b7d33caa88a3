"""Which features do a model's adapters change under g -1.6 for a run? python featdiff.py MODEL EDIT_T FOOT_LOCK

The check's first run prompt x 4 samples, 120 frames, seed 7950, under Earth and g -1.6 with the same noise (DDIM 50,
eta 1, guidance 2.5, the model's alpha, edit anchor at EDIT_T). Per HumanML3D feature group: mean, std and the RMS of
the Earth/low-g difference; the contact labels per foot joint; the height range (m) of the four foot joints' ric y
channels (frames x joints, metres, Y-up) and the root height. Plain text on stdout."""
import json
import sys

import numpy as np
import torch

from simdiff.eval.model_check.config import SPEED_PROMPTS
from simdiff.model.generator import MotionGenerator
from simdiff.motion.features import SLICES
from simdiff.motion.skeleton import FOOT_LEFT, FOOT_RIGHT


def main() -> None:
    torch.set_num_threads(2)
    model, edit_t, foot_lock = sys.argv[1], int(sys.argv[2]), float(sys.argv[3])
    s = json.loads(open(f"{model}/sampling.json").read())
    gen, prompt, out = MotionGenerator.load(model), SPEED_PROMPTS["run"][0], {}
    for g in (-9.81, -1.6):
        out[g] = gen.generate([prompt] * 4, 120, seed=7950, steps=50, guidance=2.5, eta=1.0, alpha=s["alpha"],
                              foot_lock=foot_lock, env=[g, 0.0, 0.0], env_guidance=1.0, anchor="edit",
                              anchor_alpha=0.0, edit_t=edit_t).features.numpy()
    a, b = out[-9.81], out[-1.6]
    for k, sl in SLICES.items():
        print(f"{k}: earth mean {a[..., sl].mean():.3f} std {a[..., sl].std():.3f} | low g mean {b[..., sl].mean():.3f} "
              f"std {b[..., sl].std():.3f} | rms diff {np.sqrt(((a[..., sl] - b[..., sl]) ** 2).mean()):.3f}")
    c = SLICES["contacts"]
    print("contact per foot joint: earth", a[..., c].mean((0, 1)).round(2), "low g", b[..., c].mean((0, 1)).round(2))
    for j in sorted((*FOOT_LEFT, *FOOT_RIGHT)):  # ric holds joints 1..21; y of joint j at its start + 3 (j - 1) + 1
        y = SLICES["ric"].start + 3 * (j - 1) + 1
        print(f"joint {j} height range earth {np.ptp(a[..., y], 1).mean():.3f} low g {np.ptp(b[..., y], 1).mean():.3f}, "
              f"mean {a[..., y].mean():.3f} / {b[..., y].mean():.3f}")
    print(f"root y {a[..., 3].mean():.3f} / {b[..., 3].mean():.3f}")


if __name__ == "__main__":
    main()
