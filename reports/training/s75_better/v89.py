"""Rule 89's C''' verdict: X88 against the shipped model on the low-gravity reference corpus (exit 0 on a pass).
python v89.py CANDIDATE_DIR SHIPPED_DIR   (each a guard.py model-check folder with check.json)"""
from __future__ import annotations

import json
import sys
from pathlib import Path


def figures(folder: str) -> tuple[float, float, bool]:
    """(R@3, FID, the check's own R@3 verdict) of one report."""
    rep = json.loads((Path(folder) / "check.json").read_text())
    r3 = next(v for v in rep["verdicts"] if v["check"] == "r_precision_top3")
    return rep["figures"]["r_precision_top3"], rep["figures"]["fid"], bool(r3["passed"])


def main(cand: str, shipped: str) -> bool:
    r_c, f_c, own = figures(cand)
    r_s, f_s, _ = figures(shipped)
    ok = own and r_c >= r_s and f_c <= f_s
    print(f"C''' candidate R@3 {r_c:.4f} (own bar {'pass' if own else 'FAIL'}) FID {f_c:.3f}; "
          f"shipped R@3 {r_s:.4f} FID {f_s:.3f} -> {'PASS' if ok else 'FAIL'}")
    return ok


if __name__ == "__main__":
    sys.exit(0 if main(*sys.argv[1:]) else 1)
