"""Do source-anchored targets take height out of the weak-gravity jumps? python target_apex.py [SCRATCH]
(default /work/scratch/s39: corpus3/ and aug_weakg/). Apex = the pelvis's highest point above its median height (m),
for each first-try Earth item of aug_weakg (its replay) against its source clip, and for the low-gravity replays."""
import json
import sys
from pathlib import Path

import numpy as np

root = Path(sys.argv[1] if len(sys.argv) > 1 else "/work/scratch/s39")
env = json.loads((root / "aug_weakg/env.json").read_text())
kept = set((root / "aug_weakg/first_try.txt").read_text().split())


def apex(name: str, folder: str) -> float:
    y = np.load(root / folder / "new_joints" / f"{name}.npy")[:, 0, 1]
    return float(y.max() - np.median(y))


earth = [(k, v["source"]) for k, v in env.items() if v["factor"] == "earth" and k in kept]
src = np.array([apex(s, "corpus3") for _, s in earth])
rep = np.array([apex(k, "aug_weakg") for k, _ in earth])
sources = {s for _, s in earth}
low = [apex(k, "aug_weakg") for k, v in env.items() if v["factor"] != "earth" and k in kept and v["source"] in sources]
d = rep - src
print(f"Earth items {len(earth)}: apex source {np.median(src):.3f} m, Earth replay {np.median(rep):.3f} m, "
      f"paired {np.median(d):+.3f} (IQR {np.percentile(d, 25):+.3f} .. {np.percentile(d, 75):+.3f}); "
      f"low-gravity replays {len(low)}: {np.median(low):.3f} m")
