"""Val-split quality (R@3, FID) of samples generated under a non-Earth φ: model_check with EARTH replaced."""
import os
import sys
import torch
import simdiff.eval.model_check.run as R
from simdiff.eval.model_check import CheckConfig, ModelCheck
from simdiff.eval.model_check.config import PromptOptions, ResponseOptions, SplitOptions

phi = tuple(float(v) for v in sys.argv[1].split(","))
se, out = float(sys.argv[2]), sys.argv[3]
torch.set_num_threads(2)
R.EARTH = phi
E = os.environ.get("SIMDIFF_SCRATCH", "/work/scratch/s29")  # session 39: the corpus3/ and eval/ folder
model = sys.argv[4] if len(sys.argv) > 4 else "simdiff/assets/default_model"  # session 38: another model folder
c = CheckConfig(model=model, corpus=f"{E}/corpus3", evaluator=f"{E}/eval", out=out,
                seeds=[int(v) for v in os.environ.get("SEEDS", "0").split()],  # session 56: SEEDS="1 2"
                steps=int(os.environ.get("STEPS", "20")), guidance=float(os.environ.get("W", "2.5")),  # session 46
                alpha=float(os.environ.get("ALPHA", "0.5")), foot_lock=1.0, env_guidance=se,  # ALPHA: session 54
                anchor=os.environ.get("ANCHOR", "adapters"),  # session 47
                anchor_alpha=float(os.environ.get("ANCHOR_ALPHA", "0")),  # session 55
                ballistic=float(os.environ.get("BALLISTIC") or 0),  # session 67
                edit_t=int(os.environ["EDIT_T"]) if os.environ.get("EDIT_T") else None,  # session 70
                eta=float(os.environ.get("ETA") or 0),  # session 70
                split=SplitOptions(split="val", n=128), prompts=PromptOptions(jump_samples=16, speed_samples=8),
                response=ResponseOptions(enabled=False))
rep = ModelCheck(c.validate(), progress=False, command=sys.argv).run()
f = rep["figures"]
print(phi, se, {k: f.get(k) for k in ("r_precision_top3", "fid", "jump_fraction", "sliding_own_floor", "skate_ratio", "walk_median", "run_median",
                                  "floating", "never_touch")})
