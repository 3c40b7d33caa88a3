"""Session 82: two fixes to the shipped provenance.json after ship98.sh (X96's weights).

1. X96's adapter entries carried only the session-79 re-fit in their note; the history before it (sessions 63-74, kept
   in X93's record) is put back in front of it.
2. One backbone entry named ``corpus`` has no note. It came in with session 78's weights; its hours and licences are
   corpus3's train split's. It is said so, without guessing more.
Usage: python provenance82.py simdiff/assets/default_model/provenance.json   (idempotent)"""
from __future__ import annotations

import json
import sys

HISTORY = ("sessions 63-74: the adapters fine-tuned 3,000 steps of batch 128 on one H200 with the 8-layer backbone "
           "(aug_weakg, half of aug_gen, aug_wind; s63_deepen), then on 2 CPU cores 600 steps of batch 64 with crossed "
           "twins on aug_lowg, aug_weakg, aug_wind, aug_gen (s70_cross), 300 more adding aug_lowloc (s72_lowloc, "
           "rebuilt in s73_edit_scale) and 300 more adding aug_lowgen (s74_sim_reference)")
S79 = "; session 79:"
CORPUS_NOTE = ("an entry carried in with session 78's weights: the same hours and licences as corpus3's train split "
               "above; no further data")


def main(path: str) -> None:
    p = json.load(open(path))
    for e in p["trained_on"]:
        note = e.get("note", "")
        if e["what"] == "adapters" and S79 in note and "sessions 63-74" not in note:
            head, tail = note.split(S79, 1)
            e["note"] = f"{head}; {HISTORY}{S79}{tail}"
        elif e["what"] == "backbone" and e["data"] == "corpus" and not note:
            e["note"] = CORPUS_NOTE
    open(path, "w").write(json.dumps(p, indent=2) + "\n")


if __name__ == "__main__":
    main(sys.argv[1])
