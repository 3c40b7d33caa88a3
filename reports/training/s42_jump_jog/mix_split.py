"""Session 42: a train split that repeats jump clips (more so in-place jumps) and jog clips (issue 14).

Jump clips are those of session 41's ``jump_split.py`` (train ids whose captions name a jump, hop or leap and that
fly at least 0.2 s, split ``train_flight``). In-place jumps are those among them whose root ends less than 0.5 m
(horizontally) from where it started. Jog clips are train ids with a caption containing "jog". The output lists every
train id once, then the jump ids ``JUMP - 1`` more times, the in-place jump ids ``IN_PLACE`` more times on top and the
jog ids ``JOG - 1`` more times.
Usage: python mix_split.py CORPUS JUMP IN_PLACE JOG > CORPUS/train_mix.txt   (a summary goes to stderr)
"""
import re
import sys
from pathlib import Path

import numpy as np

from simdiff.data.humanml3d import read_captions, read_split

JUMP = re.compile(r"\b(jump|jumps|jumping|jumped|hop|hops|hopping|hopped|leap|leaps|leaping|leapt)\b", re.I)
JOG = re.compile(r"\bjog", re.I)
IN_PLACE_M = 0.5


def captions(root: Path, clip: str) -> list[str]:
    path = root / "texts" / f"{clip}.txt"
    return [c.text for c in read_captions(path)] if path.is_file() else []


def displacement(root: Path, clip: str) -> float:
    """Horizontal distance (m) between the root's first and last positions (new_joints: frames x 22 x 3, Y-up)."""
    joints = np.load(root / "new_joints" / f"{clip}.npy")
    return float(np.linalg.norm(joints[-1, 0, [0, 2]] - joints[0, 0, [0, 2]]))


def main() -> None:
    root = Path(sys.argv[1])
    jump_x, in_place_x, jog_x = (int(a) for a in sys.argv[2:5])
    train = read_split(root / "train.txt")
    flight = set(read_split(root / "train_flight.txt"))
    jumps = [c for c in train if c in flight and any(JUMP.search(t) for t in captions(root, c))]
    in_place = [c for c in jumps if displacement(root, c) < IN_PLACE_M]
    jogs = [c for c in train if any(JOG.search(t) for t in captions(root, c))]
    ids = train + jumps * (jump_x - 1) + in_place * in_place_x + jogs * (jog_x - 1)
    print("\n".join(ids))
    n = len(ids)
    print(f"{len(train)} train ids; {len(jumps)} jump ids x{jump_x}, {len(in_place)} of them in place "
          f"+{in_place_x}; {len(jogs)} jog ids x{jog_x}: jumps {(len(jumps) * jump_x + len(in_place) * in_place_x) / n:.3f}, "
          f"jogs {len(jogs) * jog_x / n:.3f} of {n} draws", file=sys.stderr)


if __name__ == "__main__":
    main()
