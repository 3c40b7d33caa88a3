"""Wind signal in an augmented corpus: root drift along the wind of each wind rollout minus its Earth rollout.

Usage: python wind_signal.py AUG_DIR [CORPUS_DIR]   (AUG_DIR: a `simdiff data augment` output with env.json and
new_joints/; CORPUS_DIR: its corpus, whose manifest.json gives each source clip's motion_type)
Prints quartiles of the drift per 10 N over the clip and per second (metres; HumanML3D axes: w_x → +X, w_y → +Z),
and per motion type when the corpus is given.
"""

import json
import sys
from pathlib import Path

import numpy as np

root = Path(sys.argv[1])
types: dict[str, str] = {}
if len(sys.argv) > 2:
    manifest = json.loads((Path(sys.argv[2]) / "manifest.json").read_text())
    types = {c["id"]: str(c.get("motion_type")) for c in manifest["clips"]}
env = json.loads((root / "env.json").read_text())
by_source: dict[str, dict[int, tuple[str, dict]]] = {}
for key, value in env.items():
    by_source.setdefault(value["source"], {})[value["condition"]] = (key, value)
per_clip, per_second, seconds = [], [], []
by_type: dict[str, list[float]] = {}
for source, conds in by_source.items():
    if 0 not in conds or not (root / "new_joints" / f"{conds[0][0]}.npy").is_file():
        continue
    earth = np.load(root / "new_joints" / f"{conds[0][0]}.npy")
    for key, value in conds.values():
        path = root / "new_joints" / f"{key}.npy"
        if value["factor"] not in ("wind_x", "wind_y") or not path.is_file():
            continue
        joints = np.load(path)
        n = min(len(joints), len(earth))
        axis, w = (0, value["env"][1]) if value["factor"] == "wind_x" else (2, value["env"][2])
        if abs(w) < 2 or n < 10:  # too weak a wind or too short a clip to read a drift
            continue
        drift = (joints[n - 1, 0, axis] - joints[0, 0, axis]) - (earth[n - 1, 0, axis] - earth[0, 0, axis])
        per_clip.append(drift * np.sign(w) * 10 / abs(w))
        per_second.append(per_clip[-1] / (n / 20))
        seconds.append(n / 20)
        by_type.setdefault(types.get(source, "?"), []).append(per_second[-1])
q = [25, 50, 75]
print(f"pairs {len(per_clip)}; downwind {np.mean(np.array(per_clip) > 0):.3f}")
print("clip seconds", np.round(np.percentile(seconds, q), 2))
print("drift per 10 N over the clip (m)", np.round(np.percentile(per_clip, q), 4))
print("drift per 10 N per second (m/s)", np.round(np.percentile(per_second, q), 4))
if types:
    for kind, rates in sorted(by_type.items(), key=lambda item: -len(item[1])):
        print(f"  {kind}: {len(rates)} pairs, per second", np.round(np.percentile(rates, q), 4))
