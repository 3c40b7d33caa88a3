"""Session 58: a corpus of the model's own Earth jumps, for the simulator to replay under low gravity.

For every train-split clip of a HumanML3D-layout corpus with a jump / hop / leap caption (mirrors included), one
sample of ``frames`` frames at Earth without wind, with the model's ``sampling.json`` settings (batches of ``batch``,
seed = the batch's first row),
captioned with that clip's first such caption (its line copied verbatim). Written in the HumanML3D layout
(``new_joint_vecs/g####.npy`` un-normalised (T, 263) features, ``texts/``, ``train.txt``, the corpus's Mean/Std) so
``simdiff data augment`` can replay it. Only train captions are used; val and test are not read.

    python gen_jumps.py MODEL CORPUS OUT [--frames 120] [--batch 32]
"""

from __future__ import annotations

import argparse
import json
import re
import shutil
import sys
import time
from pathlib import Path

import numpy as np
import torch

JUMP = re.compile(r"\b(jump|jumps|jumping|jumped|hop|hops|hopping|leap|leaps|leaping)\b")


def jump_rows(corpus: Path) -> list[tuple[str, str]]:
    """(clip id, caption line) for every train clip with a jump caption, in split order."""
    rows = []
    for clip in (l.strip() for l in (corpus / "train.txt").read_text().splitlines()):
        if not clip:
            continue
        for line in (corpus / "texts" / f"{clip}.txt").read_text(encoding="utf-8").splitlines():
            if JUMP.search(line.split("#")[0].lower()):
                rows.append((clip, line))
                break
    return rows


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("model", type=Path)
    p.add_argument("corpus", type=Path)
    p.add_argument("out", type=Path)
    p.add_argument("--frames", type=int, default=120)
    p.add_argument("--batch", type=int, default=32)
    args = p.parse_args()
    from simdiff.model.generator import MotionGenerator

    torch.manual_seed(0)
    settings = json.loads((args.model / "sampling.json").read_text())
    gen = MotionGenerator.load(args.model)
    rows = jump_rows(args.corpus)
    out = args.out
    (out / "new_joint_vecs").mkdir(parents=True, exist_ok=True)
    (out / "texts").mkdir(exist_ok=True)
    for name in ("Mean.npy", "Std.npy"):
        shutil.copy(args.corpus / name, out / name)
    kw = dict(alpha=float(settings.get("alpha", 1.0)), guidance=float(settings.get("guidance", 2.5)),
              steps=int(settings.get("steps", 50)), foot_lock=float(settings.get("foot_lock", 0.0)))
    start = time.perf_counter()
    ids = [f"g{i:04d}" for i in range(len(rows))]
    for b0 in range(0, len(rows), args.batch):
        todo = [i for i in range(b0, min(b0 + args.batch, len(rows)))
                if not (out / "new_joint_vecs" / f"{ids[i]}.npy").is_file()]
        if not todo:
            continue
        texts = [rows[i][1].split("#")[0] for i in todo]
        g = gen.generate(texts, args.frames, env=(-9.81, 0.0, 0.0), seed=b0, **kw)  # one noise draw per batch
        for i, clip in zip(todo, g.clips()):
            feats = clip.detach().cpu().numpy().astype(np.float32)
            (out / "texts" / f"{ids[i]}.txt").write_text(rows[i][1] + "\n", encoding="utf-8")
            tmp = out / "new_joint_vecs" / f"{ids[i]}.tmp.npy"
            np.save(tmp, feats)
            tmp.replace(out / "new_joint_vecs" / f"{ids[i]}.npy")
        print(f"{min(b0 + args.batch, len(rows))}/{len(rows)} in {time.perf_counter() - start:.0f} s", flush=True)
    (out / "train.txt").write_text("".join(f"{i}\n" for i in ids))
    (out / "all.txt").write_text("".join(f"{i}\n" for i in ids))
    (out / "selfgen.json").write_text(json.dumps({
        "model": str(args.model), "corpus": str(args.corpus), "frames": args.frames, "sampling": kw,
        "env": [-9.81, 0.0, 0.0], "seeds": "first row of each batch", "batch": args.batch, "rows": [{"id": i, "source": r[0]} for i, r in zip(ids, rows)],
    }, indent=1))
    print(f"wrote {len(ids)} motions to {out}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
