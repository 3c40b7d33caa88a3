"""Corpus3 train clips: root speed (m/s) by motion_type and by caption verb (descriptive, session 64)."""
import json, statistics, sys
from pathlib import Path
import numpy as np, torch
from simdiff.eval.model_check.detect import root_speed
from simdiff.motion.features import features_to_joints
c = Path(sys.argv[1])
man = json.loads((c / "manifest.json").read_text())["clips"]
rows = {}
for m in man:
    if m.get("split") != "train" or m["motion_type"] not in ("run", "walk"): continue
    caps = " ".join(l.split("#")[0] for l in (c / "texts" / f"{m['id']}.txt").read_text().lower().splitlines())
    tag = m["motion_type"] + ("/jog" if "jog" in caps else "/run" if "run" in caps else "/other")
    f = np.load(c / "new_joint_vecs" / f"{m['id']}.npy")
    rows.setdefault(tag, []).append(root_speed(features_to_joints(torch.from_numpy(f).double()).numpy()))
for k, v in sorted(rows.items()):
    q = np.percentile(v, [25, 50, 75])
    print(f"{k}: n {len(v)}, q1 {q[0]:.2f} median {q[1]:.2f} q3 {q[2]:.2f}")
