"""Session 41: a train split that repeats the jump clips (issue 14, Earth jumps).

Jump clips: train ids (originals and mirrors) whose captions name a jump, hop or leap and that are in the
``train_flight`` split (a flight of at least 0.2 s, session 29). The output lists every train id once, then the
jump ids ``REPEAT - 1`` more times, so a uniform draw picks a jump clip REPEAT times as often as before.
Usage: python jump_split.py CORPUS REPEAT > CORPUS/train_jumpx.txt   (a summary goes to stderr)
"""
import re
import sys
from pathlib import Path

from simdiff.data.humanml3d import read_captions, read_split

WORD = re.compile(r"\b(jump|jumps|jumping|jumped|hop|hops|hopping|hopped|leap|leaps|leaping|leapt)\b", re.I)


def captions(root: Path, clip: str) -> list[str]:
    path = root / "texts" / f"{clip}.txt"
    return [c.text for c in read_captions(path)] if path.is_file() else []


def main() -> None:
    root, repeat = Path(sys.argv[1]), int(sys.argv[2])
    train = read_split(root / "train.txt")
    flight = set(read_split(root / "train_flight.txt"))
    jumps = [c for c in train if c in flight and any(WORD.search(t) for t in captions(root, c))]
    print("\n".join(train + jumps * (repeat - 1)))
    n = len(train) + len(jumps) * (repeat - 1)
    print(f"{len(train)} train ids, {len(jumps)} jump ids with flight, repeat {repeat}: "
          f"{len(jumps) * repeat} / {n} = {len(jumps) * repeat / n:.3f} of draws", file=sys.stderr)


if __name__ == "__main__":
    main()
