"""Rule 71's stage C' verdict (evaluator 1): python c71.py NAME (e.g. G63_se4). NAME's and the shipped model's
(J40m_se4) val-caption checks under g -1.6 at seeds 1 2 (eval11/C12_*) and 3 4 (eval11/C34_*), n 128 per seed: pass
when the 4-seed mean R@3 >= shipped's - 0.03 and the 4-seed mean FID <= 1.25 x shipped's. Exit 0 on a pass."""
import json
import sys

from simdiff.eval.stats import t_interval

ROOT = "/work/scratch/s39/eval11"


def per_seed(name: str, key: str) -> list[float]:
    out = []
    for part in ("C12", "C34"):
        rep = json.load(open(f"{ROOT}/{part}_{name}/-1.6,0,0/check.json"))["test_split"]
        out += [s[key] for s in rep["per_seed"]["generated"]]
    return out


name = sys.argv[1]
fails = []
for key, rule in (("r_precision_top3", "r"), ("fid", "f")):
    a, b = per_seed(name, key), per_seed("J40m_se4", key)
    ma, mb = sum(a) / len(a), sum(b) / len(b)
    m, h = t_interval([x - y for x, y in zip(a, b)])
    bar = mb - 0.03 if rule == "r" else 1.25 * mb
    ok = ma >= bar if rule == "r" else ma <= bar
    print(f"C' g -1.6 seeds 1-4 {key}: {name} {ma:.3f} (shipped {mb:.3f}, bar {bar:.3f}) -> {'pass' if ok else 'FAIL'}; "
          f"per seed {['%.3f' % v for v in a]} vs {['%.3f' % v for v in b]}, paired {m:+.3f} +- {h:.3f} "
          f"(Student-t 95 %, {len(a)} seeds)")
    if not ok:
        fails.append(key)
print(f"C' (rule 71): {name} -> {'PASS' if not fails else 'FAIL: ' + ', '.join(fails)}")
sys.exit(1 if fails else 0)
