"""Corpus3 train clips of motion_type run with 'run'/'jog' in a caption: root speed by clip length (session 65,
descriptive). python corpus_speed_by_length.py CORPUS3 > corpus_speed_by_length.txt"""
import json, statistics, sys
from pathlib import Path
import numpy as np, torch
from simdiff.eval.model_check.detect import root_speed
from simdiff.motion.features import features_to_joints
c = Path(sys.argv[1])
man = json.loads((c / "manifest.json").read_text())["clips"]
rows = []
for m in man:
    if m.get("split") != "train" or m["motion_type"] != "run": continue
    caps = " ".join(l.split("#")[0] for l in (c / "texts" / f"{m['id']}.txt").read_text().lower().splitlines())
    if "run" not in caps and "jog" not in caps: continue
    f = np.load(c / "new_joint_vecs" / f"{m['id']}.npy")
    rows.append((len(f), root_speed(features_to_joints(torch.from_numpy(f).double()).numpy())))
print(f"corpus3 train, motion_type run, caption has run/jog: n {len(rows)}, frames median {statistics.median(r[0] for r in rows)}")
for lo, hi in ((0, 60), (60, 100), (100, 140), (140, 200), (200, 10000)):
    v = [s for n, s in rows if lo <= n < hi]
    if v:
        q = np.percentile(v, [25, 50, 75])
        print(f"  frames [{lo}, {hi}): n {len(v)}, speed q1 {q[0]:.2f} median {q[1]:.2f} q3 {q[2]:.2f}")
v = [s for n, s in rows if n >= 120]
print(f"  frames >= 120: n {len(v)}, median {statistics.median(v):.2f}" if v else "none >= 120")
