"""Session 52: how many corpus clips glide or never touch the floor (the false-positive rate of the two measures on
real mocap). numpy only. Usage: python corpus_glides.py CORPUS (e.g. /work/scratch/s39/corpus3)."""
import sys
from pathlib import Path

import numpy as np

from simdiff.motion.metrics import glides, never_touches

root = Path(sys.argv[1])
ids = [i for s in ("train", "val", "test") for i in (root / f"{s}.txt").read_text().split()]
n = glide = floats = 0
for clip in ids:
    path = root / "new_joints" / f"{clip}.npy"
    if not path.is_file():
        continue
    joints = np.load(path)
    if len(joints) < 2:
        continue
    n += 1
    glide += int(glides(joints)[0])
    floats += int(never_touches(joints)[0])
print(f"{n} clips (train + val + test, with mirrors): {glide} glide, {floats} never touch the floor")
