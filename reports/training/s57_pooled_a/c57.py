"""Rule 57's stage C'' verdict: X15sa vs the shipped model under g -1.6, val n 128, four replications pooled (seeds 1 2
from eval11/C12_*, seeds 3 4 from eval11/C34_*), evaluator 1. Exit 0 on a pass."""
import json
import sys

from simdiff.eval.stats import t_interval

ROOT, PHI = "/work/scratch/s39/eval11", "-1.6,0,0"


def per_seed(name: str, key: str) -> list[float]:
    out = []
    for part in ("C12", "C34"):
        ts = json.load(open(f"{ROOT}/{part}_{name}/{PHI}/check.json"))["test_split"]
        out += [s[key] for s in ts["per_seed"]["generated"]]
    return out


ok = True
for key, bar in (("r_precision_top3", lambda b: b - 0.03), ("fid", lambda b: 1.25 * b)):
    a, b = per_seed("X15sa_se4", key), per_seed("J40m_se4", key)
    ma, mb = sum(a) / len(a), sum(b) / len(b)
    passed = ma >= bar(mb) if key == "r_precision_top3" else ma <= bar(mb)
    ok &= passed
    m, h = t_interval([x - y for x, y in zip(a, b)])
    print(f"C'' g -1.6 seeds 1-4 {key}: X15sa {ma:.3f} {['%.3f' % v for v in a]}, shipped {mb:.3f} "
          f"{['%.3f' % v for v in b]}, bar {bar(mb):.3f}, paired {m:+.3f} +- {h:.3f} -> {'PASS' if passed else 'FAIL'}")
print("C'':", "PASS" if ok else "FAIL")
sys.exit(0 if ok else 1)
