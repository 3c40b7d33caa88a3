"""Session 48: a train split that repeats the jump clips, the jumps in place most (issue 14, Earth jumps).

Jump clips as session 41 (``../s41_jump_backbone/jump_split.py``): train ids (originals and mirrors) whose captions
name a jump, hop or leap and that are in ``train_flight`` (a flight of at least 0.2 s). A jump clip is **in place**
when its pelvis ends less than 0.5 m (horizontally) from where it starts. The output lists every train id once, the
jump ids ``REPEAT - 1`` more times and the in-place jump ids ``INPLACE - REPEAT`` more times on top.
Usage: python jump_split.py CORPUS REPEAT INPLACE > CORPUS/train_jumpy.txt   (a summary goes to stderr)
"""
import re
import sys
from pathlib import Path

import numpy as np

from simdiff.data.humanml3d import read_captions, read_split

WORD = re.compile(r"\b(jump|jumps|jumping|jumped|hop|hops|hopping|hopped|leap|leaps|leaping|leapt)\b", re.I)
IN_PLACE_M = 0.5


def captions(root: Path, clip: str) -> list[str]:
    path = root / "texts" / f"{clip}.txt"
    return [c.text for c in read_captions(path)] if path.is_file() else []


def in_place(root: Path, clip: str) -> bool:
    """Whether the clip's pelvis ends < IN_PLACE_M from where it starts (X-Z, metres)."""
    joints = np.load(root / "new_joints" / f"{clip}.npy")
    return bool(np.linalg.norm(joints[-1, 0, [0, 2]] - joints[0, 0, [0, 2]]) < IN_PLACE_M)


def main() -> None:
    root, repeat, inplace = Path(sys.argv[1]), int(sys.argv[2]), int(sys.argv[3])
    if not 1 <= repeat <= inplace:
        sys.exit(f"jump_split.py: need 1 <= REPEAT <= INPLACE, got {repeat} and {inplace}")
    train = read_split(root / "train.txt")
    flight = set(read_split(root / "train_flight.txt"))
    jumps = [c for c in train if c in flight and any(WORD.search(t) for t in captions(root, c))]
    still = [c for c in jumps if in_place(root, c)]
    lines = train + jumps * (repeat - 1) + still * (inplace - repeat)
    print("\n".join(lines))
    print(f"{len(train)} train ids, {len(jumps)} jump ids with flight ({len(still)} in place), repeat {repeat} / "
          f"{inplace}: jumps {(len(jumps) * repeat + len(still) * (inplace - repeat)) / len(lines):.3f} of draws, "
          f"in place {len(still) * inplace / len(lines):.3f}", file=sys.stderr)


if __name__ == "__main__":
    main()
