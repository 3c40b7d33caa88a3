"""How often corpus3's train clips whose captions name a walk / sitting / waving / kick / dance / turn (and no jump,
hop, leap or skip) jump by the checker's rule (flight >= 0.2 s, pelvis >= 15 cm): the ground truth's rate of
'spurious' jumps for nonjump_probe.py's prompt kinds. Clips are cut to their first 120 frames (the probe's length)."""
import re, sys
from pathlib import Path
import numpy as np
from simdiff.eval.model_check.detect import jump_stats
root = Path(sys.argv[1])
ids = [l.strip() for l in open(root / "train.txt") if l.strip()]
kinds = {"walk": r"\bwalk", "wave": r"\bwav", "sit": r"\bsit", "kick": r"\bkick", "dance": r"\bdanc", "turn": r"\bturn"}
no = re.compile(r"jump|hop|leap|skip")
counts = {k: [0, 0] for k in kinds}
for i in ids:
    caps = " ".join(l.split("#")[0].lower() for l in open(root / "texts" / f"{i}.txt"))
    if no.search(caps):
        continue
    hit = [k for k, r in kinds.items() if re.search(r, caps)]
    if not hit:
        continue
    j = np.load(root / "new_joints" / f"{i}.npy")[:120]
    if len(j) < 20:
        continue
    jumped = bool(jump_stats(j)["jump"])
    for k in hit:
        counts[k][0] += jumped; counts[k][1] += 1
for k, (a, b) in counts.items():
    print(f"{k}: {a}/{b} = {a / max(b, 1):.3f}")
