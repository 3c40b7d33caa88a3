"""Split file of session 40's wind augmentation: 150 walk/run train originals (not in train_sub300) + mirrors.

Usage: python walk_split.py CORPUS_DIR > train_walk150.txt   (CORPUS_DIR: corpus3 with train.txt, train_sub300.txt
and manifest.json; the draw is random.Random(40).sample over the sorted candidate ids, so it is reproducible)
"""

import json
import random
import sys
from pathlib import Path

corpus = Path(sys.argv[1])
manifest = json.loads((corpus / "manifest.json").read_text())
train = set((corpus / "train.txt").read_text().split())
taken = set((corpus / "train_sub300.txt").read_text().split())
candidates = sorted(c["id"] for c in manifest["clips"] if c["id"] in train and c["id"] not in taken
                    and c.get("motion_type") in ("walk", "run") and not c["id"].startswith("M"))
for clip in sorted(random.Random(40).sample(candidates, 150)):
    print(clip)
    if "M" + clip in train:
        print("M" + clip)
