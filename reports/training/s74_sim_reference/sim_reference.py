"""Session 74 (rule 87): a reference corpus whose val split is the simulator's answer under low gravity.

Every file of CORPUS is linked into OUT/corpus3; each val id whose low-gravity replay AUG kept (env.json factor
'gravity') gets that replay's features (new_joint_vecs, 263-d) and joints (new_joints, frames x 22 x 3, metres, Y-up,
20 fps) instead, captions unchanged; OUT/corpus3/val.txt lists only those ids. OUT/eval links the evaluator, so the
model check (via guard.py with SIMDIFF_SCRATCH=OUT) scores samples against the replays.
python sim_reference.py CORPUS AUG EVALUATOR OUT"""
from __future__ import annotations

import json
import os
import sys
from pathlib import Path

corpus, aug, evaluator, out = (Path(a).resolve() for a in sys.argv[1:5])
dst = out / "corpus3"
for sub in ("new_joint_vecs", "new_joints", "texts"):
    (dst / sub).mkdir(parents=True, exist_ok=True)
env = json.loads((aug / "env.json").read_text())
replay = {v["source"]: k for k, v in sorted(env.items()) if v["factor"] == "gravity"}
val = (corpus / "val.txt").read_text().split()
kept = [i for i in val if i in replay]
for f in corpus.iterdir():
    if f.is_file() and f.name != "val.txt" and not (dst / f.name).exists():
        os.symlink(f, dst / f.name)
for sub in ("new_joint_vecs", "new_joints", "texts"):
    for f in (corpus / sub).iterdir():
        link = dst / sub / f.name
        if link.is_symlink():
            link.unlink()
        src = aug / sub / f"{replay[f.stem]}.npy" if sub != "texts" and f.stem in replay else f
        os.symlink(src, link)
(dst / "val.txt").write_text("\n".join(kept) + "\n")
if not (out / "eval").exists():
    os.symlink(evaluator, out / "eval")
g = [env[replay[i]]["env"][0] for i in kept]
re = sum(1 for i in kept if env[replay[i]].get("retime_scale"))
print(json.dumps({"val": len(val), "kept_low_g": len(kept), "retimed": re, "g_min": min(g), "g_max": max(g)}))
