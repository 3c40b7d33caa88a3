"""Session 48's check of the text side: for each prompt, the 12 corpus train captions nearest in the text encoder's
space (cosine), with whether the clip they describe jumps (simdiff.eval.model_check.detect.jump_stats).
Usage: python caption_neighbours.py CORPUS CAPTION_TABLE PROMPT [PROMPT ...]   (CAPTION_TABLE: a --text-table file)
"""
import sys
from pathlib import Path

import numpy as np
import torch

from simdiff.data.humanml3d import read_captions, read_split
from simdiff.eval.model_check.detect import jump_stats
from simdiff.text.base import load_text_encoder
from simdiff.text.cache import read_caption_file


def main() -> None:
    root, prompts = Path(sys.argv[1]), sys.argv[3:]
    captions, table, encoder = read_caption_file(sys.argv[2])
    owner: dict[str, str] = {}
    for clip in read_split(root / "train.txt"):
        path = root / "texts" / f"{clip}.txt"
        for c in read_captions(path) if path.is_file() else []:
            owner.setdefault(c.text, clip)
    rows = [i for i, c in enumerate(captions) if c in owner]
    keys = torch.nn.functional.normalize(table[rows].float(), dim=-1)
    query = torch.nn.functional.normalize(load_text_encoder(encoder).encode(prompts).float(), dim=-1)
    for prompt, q in zip(prompts, query):
        sims = keys @ q
        print(f"== {prompt}")
        for k in sims.argsort(descending=True)[:12].tolist():
            text = captions[rows[k]]
            s = jump_stats(np.load(root / "new_joints" / f"{owner[text]}.npy"))
            print(f"  {sims[k]:.3f} jump={int(s['jump'])} flight={s['flight_s']:.2f} {owner[text]} {text[:90]}")


if __name__ == "__main__":
    main()
