"""Rule 89's C''' verdict: X88 against the shipped model on the low-gravity reference corpus (exit 0 on a pass).
python v89.py CANDIDATE_DIR SHIPPED_DIR [--margin M]   (each a guard.py model-check folder with check.json)
M: how far the candidate's R@3 may fall below the shipped model's (rule 89/90: 0; rule 91: 0.03)."""
from __future__ import annotations

import json
import sys
from pathlib import Path


def figures(folder: str) -> tuple[float, float, bool]:
    """(R@3, FID, the check's own R@3 verdict) of one report."""
    rep = json.loads((Path(folder) / "check.json").read_text())
    r3 = next(v for v in rep["verdicts"] if v["check"] == "r_precision_top3")
    return rep["figures"]["r_precision_top3"], rep["figures"]["fid"], bool(r3["passed"])


def main(cand: str, shipped: str, margin: float = 0.0) -> bool:
    r_c, f_c, own = figures(cand)
    r_s, f_s, _ = figures(shipped)
    ok = own and r_c >= r_s - margin and f_c <= f_s
    print(f"C''' candidate R@3 {r_c:.4f} (own bar {'pass' if own else 'FAIL'}) FID {f_c:.3f}; "
          f"shipped R@3 {r_s:.4f} FID {f_s:.3f}, R@3 margin {margin} -> {'PASS' if ok else 'FAIL'}")
    return ok


if __name__ == "__main__":
    args = sys.argv[1:]
    m = float(args[args.index("--margin") + 1]) if "--margin" in args else 0.0
    sys.exit(0 if main(args[0], args[1], m) else 1)
