"""Session 69: write split `big79.txt` into augmented folders: every item (the Earth replay and its twins) of each
source whose Earth replay has a longest-flight apex gain >= --min-apex metres (simdiff.motion.flight.flight_stats),
among the items of --from-split. Prints counts per folder. Usage: python big_split.py FOLDER... [--min-apex 0.1]"""
import argparse, json
from pathlib import Path

import numpy as np

from simdiff.motion.flight import flight_stats

ap = argparse.ArgumentParser()
ap.add_argument("folders", nargs="+", type=Path)
ap.add_argument("--min-apex", type=float, default=0.1)
ap.add_argument("--from-split", default="adapt")
ap.add_argument("--name", default="big79")
a = ap.parse_args()
for root in a.folders:
    env = json.loads((root / "env.json").read_text())
    keep = set((root / f"{a.from_split}.txt").read_text().split())
    by: dict[str, list[str]] = {}
    for k, v in env.items():
        if k in keep:
            by.setdefault(v["source"], []).append(k)
    out, n_src, facs = [], 0, {}
    for src, items in sorted(by.items()):
        earth = [k for k in items if env[k]["factor"] == "earth"]
        if not earth:
            continue
        apex = flight_stats(np.load(root / "new_joints" / f"{earth[0]}.npy"))["apex_gain_m"]
        if apex >= a.min_apex:
            n_src += 1
            out += sorted(items)
            for k in items:
                facs[env[k]["factor"]] = facs.get(env[k]["factor"], 0) + 1
    (root / f"{a.name}.txt").write_text("\n".join(out) + "\n")
    print(f"{root}: {n_src} of {len(by)} sources with Earth apex >= {a.min_apex} m -> {len(out)} items {facs}")
