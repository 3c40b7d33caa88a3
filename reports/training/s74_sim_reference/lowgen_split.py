"""Session 74: train clips for low-gravity replays of general content (aug_lowgen): corpus3 train ids that are not in
train_flight (clips with flight), not in train_runwalk (run/jog/sprint captions + train_walk150), whose manifest motion
type is not jump or acrobatics and whose captions name no jump/hop/leap/run/jog/sprint; N originals drawn with SEED,
each with its mirror M<id> (so --share-mirrors simulates one of the two). Prints the ids, one per line.
python lowgen_split.py CORPUS [--n 250] [--seed 74]"""
from __future__ import annotations

import argparse
import json
import re
from pathlib import Path

import numpy as np

ap = argparse.ArgumentParser()
ap.add_argument("corpus", type=Path)
ap.add_argument("--n", type=int, default=250)
ap.add_argument("--seed", type=int, default=74)
a = ap.parse_args()
ids = lambda name: set((a.corpus / name).read_text().split())  # noqa: E731
train, skip = ids("train.txt"), ids("train_flight.txt") | ids("train_runwalk.txt")
clips = {c["id"]: c for c in json.loads((a.corpus / "manifest.json").read_text())["clips"]}
words = re.compile(r"jump|hop|leap|run|jog|sprint", re.I)
ok = sorted(i for i in train if not i.startswith("M") and f"M{i}" in train and i not in skip and f"M{i}" not in skip
            and clips[i]["motion_type"] not in ("jump", "acrobatics")
            and not words.search((a.corpus / "texts" / f"{i}.txt").read_text()))
pick = sorted(np.random.default_rng(a.seed).choice(ok, min(a.n, len(ok)), replace=False))
print("\n".join(x for i in pick for x in (i, f"M{i}")))
