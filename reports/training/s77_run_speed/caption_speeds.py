"""What the speed verdict compares with: the corpus clips behind the length-matched run reference, and a
caption-matched reference beside it (no verdict; session 77).

python caption_speeds.py CORPUS CHECK.json [CHECK.json ...]

For each walk/run prompt of the model check: the samples' median speed (from each check.json's per-prompt quartiles)
against (a) the verdict's reference, train clips of the prompt's motion type within [96, 150] frames, with the style
words of their first captions counted, and (b) the train clips (originals) any of whose captions is the prompt itself
("a person runs forward."), any length. Speeds: mean horizontal pelvis speed (m/s), as the model check measures them.
"""
from __future__ import annotations

import collections
import json
import sys
from pathlib import Path

import numpy as np

from simdiff.eval.model_check.detect import quartiles, root_speed
from simdiff.eval.model_check.config import SPEED_PROMPTS
from simdiff.eval.model_check.prompts import captioned_speeds, length_matched


def _fmt(q: dict) -> str:
    return f"n {q['n']}, median {q['median']:.2f} [{q['q1']:.2f}, {q['q3']:.2f}]" if q["n"] else "n 0"


def main(corpus: str, checks: list[str]) -> None:
    root = Path(corpus)
    clips = [c for c in json.loads((root / "manifest.json").read_text())["clips"]
             if c["split"] == "train" and not c.get("mirror_of")]
    speed = {c["id"]: root_speed(np.load(root / "new_joints" / f"{c['id']}.npy")) for c in clips
             if c["motion_type"] in ("walk", "run")}
    frames = {c["id"]: int(np.load(root / "new_joints" / f"{c['id']}.npy", mmap_mode="r").shape[0]) for c in clips
              if c["id"] in speed}
    captioned = captioned_speeds(root, SPEED_PROMPTS)
    reports = [(Path(p).parent.name, json.loads(Path(p).read_text())["speeds"]["types"]) for p in checks]
    for kind in ("walk", "run"):
        ids = sorted(i for i in speed if next(c for c in clips if c["id"] == i)["motion_type"] == kind)
        matched = [ids[i] for i in length_matched([frames[i] for i in ids], 120)]
        styles = collections.Counter(next(c for c in clips if c["id"] == i)["captions"][0].rstrip(".") for i in matched)
        print(f"## {kind}: the verdict's reference, {len(matched)} train clips of 96-150 frames: "
              f"{_fmt(quartiles([speed[i] for i in matched]))}")
        for caption, k in styles.most_common(6):
            print(f"   {k:4d} x '{caption}'")
        for prompt in SPEED_PROMPTS[kind]:
            print(f"'{prompt}': clips captioned so: {_fmt(quartiles(captioned[prompt]))}")
            for name, types in reports:
                print(f"    {name}: samples {_fmt(types[kind]['per_prompt'][prompt])}")


if __name__ == "__main__":
    if len(sys.argv) < 3:
        raise SystemExit(__doc__)
    main(sys.argv[1], sys.argv[2:])
