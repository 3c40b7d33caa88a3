import numpy as np, torch
from simdiff.data.augment import open_training_dataset
from simdiff.train.data import StepBatcher, StepBatches
from simdiff.train.geometric import CropConfig
from simdiff.diffusion.losses import twin_drift_mse, twin_difference_mse
import json
cfg = json.load(open("reports/training/s29_weak_gravity/train_config_pair10.json"))
crop = CropConfig(**cfg["train"]["crop"]) if "crop" in cfg["train"] else CropConfig()
ds = open_training_dataset(["/work/scratch/s29/aug_weakg", "/work/scratch/s29/aug_gen"], "s37_loco", 37)
sb = StepBatches(ds, StepBatcher(len(ds), 32, 37), 37, 0, crop, 0, 40, pairs=True)
d, full, wind = [], [], []
for s in range(40):
    b = sb.batch(s); x = b["motion"]; m = b["mask"]; p = b["paired"]
    z = torch.zeros_like(x)
    d.append(float(twin_drift_mse(z, x, m, p))); full.append(float(twin_difference_mse(z, x, m, p)))
    e = b["env"]; h = len(e) // 2
    wind.append(float((e[:h, 1:] - e[h:, 1:]).abs().max()))
print("E[(mean drift diff)^2] per channel: %.2e  twin per-frame diff MSE: %.2e" % (np.mean(d), np.mean(full)))
