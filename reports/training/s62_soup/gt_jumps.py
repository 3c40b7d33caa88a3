"""How often the corpus's own jump clips pass the model check's jump rule (session 62): python gt_jumps.py [CORPUS]
Train clips with a jump/hop caption, all and by what the caption asks (in place / up and down / long jump / forward)."""
import pathlib
import re
import sys

import numpy as np

from simdiff.eval.model_check.detect import jump_stats

root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "/work/scratch/s39/corpus3")
KINDS = {"in place": r"jump\w* (straight )?up|jump\w* in place", "up and down": r"up and down",
         "long jump": r"long jump|broad jump", "jump forward": r"jump\w* forward"}
rows = {k: [] for k in KINDS}
every = []
for i in (root / "train.txt").read_text().split():
    caps = [line.split("#")[0].lower() for line in (root / "texts" / f"{i}.txt").read_text().splitlines()]
    if not any(re.search(r"\b(jump|jumps|jumping|hop|hops|hopping)\b", c) for c in caps):
        continue
    s = jump_stats(np.load(root / "new_joints" / f"{i}.npy"))
    every.append(s["jump"])
    for k, pattern in KINDS.items():
        if any(re.search(pattern, c) and re.search(r"jump|hop", c) for c in caps):
            rows[k].append(s)
print(f"train clips with a jump/hop caption: {len(every)}, jumping by the check's rule {sum(every)}")
for k, v in rows.items():
    if v:
        print(f"{k}: {len(v)} clips, jumping {sum(s['jump'] for s in v)}, median flight "
              f"{np.median([s['flight_s'] for s in v]):.2f} s, median rise {np.median([s['rise_m'] for s in v]):.2f} m")
    else:
        print(f"{k}: no clip")
