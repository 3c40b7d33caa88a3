"""X93's provenance.json, tidied for shipping (session 77): entries repeated by warm starts kept once (the reader
does that since session 77), the session-63 backbone run's empty note filled, and the steps after it, which added
no new data folder, said in notes (lineage: reports/training/s63_deepen ... s76_lambda).

python provenance93.py IN_FOLDER OUT_FOLDER   (writes OUT_FOLDER/provenance.json; the licence is re-derived)
"""
from __future__ import annotations

import dataclasses
import sys

from simdiff.model.provenance import Provenance, read_provenance, write_provenance

G63 = ("session 63: the session-41 model deepened 4 -> 8 layers (`simdiff train deepen --seed 63`, an identity layer "
       "after each layer), then the backbone trained 6,000 steps of batch 128 on one H200 (5.2 min; lr 2e-4, EMA 0.999, "
       "seed 63) on corpus3's train split with its flying jump ids listed 8 times (train_jumpx); "
       "reports/training/s63_deepen/")
X90 = ("session 75: the session-63 backbone extrapolated away from its deepened, untrained start, "
       "G63 + 0.125 (G63 - P63) (`simdiff train extrapolate --lam 0.125`; no new data, no training); "
       "reports/training/s75_better/")
ADAPTERS = ("sessions 63-74: the adapters fine-tuned 3,000 steps of batch 128 on one H200 with the 8-layer backbone "
            "(aug_weakg, half of aug_gen, aug_wind; s63_deepen), then on 2 CPU cores 600 steps of batch 64 with crossed "
            "twins on aug_lowg, aug_weakg, aug_wind, aug_gen (s70_cross), 300 more adding aug_lowloc (s72_lowloc, "
            "rebuilt in s73_edit_scale) and 300 more adding aug_lowgen (s74_sim_reference)")


def tidy(prov: Provenance) -> Provenance:
    parts = []
    for p in prov.trained_on:
        if p.what == "backbone" and p.data == "corpus" and not p.note:
            p = dataclasses.replace(p, data="corpus3", note=G63)
        elif p.what == "adapters" and p.note.startswith("simulated from corpus corpus3; twins of unequal length"):
            p = dataclasses.replace(p, note=f"{p.note}; {ADAPTERS}")
        parts.append(p)
    first = next(p for p in parts if p.what == "backbone" and p.note == G63)
    parts.insert(parts.index(first) + 1, dataclasses.replace(first, note=X90))
    return Provenance(parts)


def main(src: str, dst: str) -> None:
    prov = read_provenance(src)
    if prov is None:
        raise SystemExit(f"{src}: no provenance.json")
    out = tidy(prov)
    if out.weights_licence != prov.weights_licence:
        raise SystemExit(f"licence changed: {prov.weights_licence!r} -> {out.weights_licence!r}")
    print(write_provenance(dst, out), len(out.trained_on), "entries;", out.weights_licence)


if __name__ == "__main__":
    if len(sys.argv) != 3:
        raise SystemExit(__doc__)
    main(sys.argv[1], sys.argv[2])
