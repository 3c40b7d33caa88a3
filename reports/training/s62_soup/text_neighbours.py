"""Do the check's jump prompts sit near jumping clips in the text space? (session 62) python text_neighbours.py MODEL
For each prompt, the 20 train captions (originals, not mirrors) nearest by cosine of the model's text encoder, and how
many of their clips jump by the check's rule."""
import pathlib
import sys

import numpy as np
import torch

from simdiff.eval.model_check.detect import jump_stats
from simdiff.model.generator import MotionGenerator

root = pathlib.Path("/work/scratch/s39/corpus3")
gen = MotionGenerator.load(sys.argv[1])
caps, ids = [], []
for i in (root / "train.txt").read_text().split():
    if not i.startswith("M"):
        for line in (root / "texts" / f"{i}.txt").read_text().splitlines():
            caps.append(line.split("#")[0]); ids.append(i)
emb = torch.nn.functional.normalize(torch.cat([gen.encode_text(caps[k:k + 256]) for k in range(0, len(caps), 256)]), dim=-1)
jumps: dict[str, bool] = {}
for p in ["a person jumps up in place", "a person jumps up and down", "a person does a long jump",
          "a person jumps forward", "a person hops forward on both feet"]:
    q = torch.nn.functional.normalize(gen.encode_text([p]), dim=-1)[0]
    top = torch.topk(emb @ q, 20).indices.tolist()
    for k in top:
        if ids[k] not in jumps:
            jumps[ids[k]] = bool(jump_stats(np.load(root / "new_joints" / f"{ids[k]}.npy"))["jump"])
    print(f"{p}: {sum(jumps[ids[k]] for k in top)} of 20 nearest captions' clips jump; nearest: "
          + "; ".join(f"{caps[k]!r} {float(emb[k] @ q):.3f}" for k in top[:3]))
