"""Session 49: paired (per-seed) test-split differences, shipped config with the inference mask (T_3_J40m) minus
without it (session 48's T3_J40w2.5s50: same weights, settings, captions and seeds), under evaluators 1-3 (Student-t
95 % over the 5 seeds). Usage: python paired.py [EVAL11_DIR]"""
import json
import sys

from simdiff.eval.stats import t_interval

S = sys.argv[1] if len(sys.argv) > 1 else "/work/scratch/s39/eval11"


def per_seed(path: str, which: int) -> list[dict]:
    ts = json.load(open(f"{S}/{path}/check.json"))["test_split"]
    return ts["per_seed"]["generated"] if which == 0 else ts["more_evaluators"][which - 1]["per_seed"]["generated"]


for which in range(3):
    for key in ("r_precision_top3", "fid"):
        new = [r[key] for r in per_seed("T_3_J40m", which)]
        old = [r[key] for r in per_seed("T3_J40w2.5s50", which)]
        m, h = t_interval([a - b for a, b in zip(new, old)])
        print(f"evaluator {which + 1} {key}: masked {sum(new) / 5:.3f} unmasked {sum(old) / 5:.3f} "
              f"paired {m:+.3f} ± {h:.3f}")
