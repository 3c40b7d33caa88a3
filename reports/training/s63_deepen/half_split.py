"""Half of an augmented corpus's split, by source clip: python half_split.py AUG [SPLIT] > AUG/first_half.txt.

Session 63 packed aug_gen's first_try split this way so that the corpus pack, three augmented packs and the repository
fit the device's 64 MiB. Ids are ``<source>_eNN`` and mirrors ``M<source>_eNN``; a clip, its twins and its mirror
share one source key; every other key in sorted order is kept (deterministic, no seed)."""
import re
import sys
from pathlib import Path

aug, split = Path(sys.argv[1]), sys.argv[2] if len(sys.argv) > 2 else "first_try"
ids = (aug / f"{split}.txt").read_text().split()
stems = {re.sub(r"_e\d+$", "", i) for i in ids if not i.startswith("M")}


def key(clip: str) -> str:
    stem = re.sub(r"_e\d+$", "", clip)
    return stem[1:] if stem.startswith("M") and stem[1:] in stems else stem


keep = set(sorted({key(i) for i in ids})[::2])
print("\n".join(i for i in ids if key(i) in keep))
