"""Session 73: rebuild session 72's split `train_runwalk` (aug_lowloc's source clips): the train clips any of whose
captions says run/jog/sprint, plus train_walk150, sorted. Usage: python runwalk_split.py CORPUS > CORPUS/train_runwalk.txt"""
import re
import sys
from pathlib import Path

root = Path(sys.argv[1])
word = re.compile(r"\b(run|runs|running|jog|jogs|jogging|sprint|sprints|sprinting)\b", re.IGNORECASE)
runs = {k for k in (root / "train.txt").read_text().split()
        if any(word.search(line.split("#")[0]) for line in (root / "texts" / f"{k}.txt").read_text().splitlines())}
walks = set((root / "train_walk150.txt").read_text().split())
print(f"runs {len(runs)}, walks {len(walks)}, union {len(runs | walks)}", file=sys.stderr)
print("\n".join(sorted(runs | walks)))
