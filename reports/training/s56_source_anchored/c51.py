"""Rule 51's stage C' and C+ verdicts (evaluator 1). Exit 0 on a pass.
python c51.py C12 [NAME]   NAME (default J40m_sa_se4) vs J40m_se4 on eval11/C12_* at g -1.6 (seeds 1 2), plus the
                           pooled n 384 description (J40m_sa_se4 only: rule 50 measured seed 0 of it)
python c51.py CPLUS [NAME] NAME at w_x +10 N (eval11/C_NAME, seed 0) against the recorded base 0.836 / 2.95
(rule 52 passes NAME = J40m_sa_se6 or J40m_sa_se8)"""
import json
import sys

from simdiff.eval.stats import t_interval

ROOT = "/work/scratch/s39/eval11"
SEED0 = {"J40m_se4": (0.812, 2.33), "J40m_sa_se4": (0.781, 2.01)}  # session 54 base; rule 50's stage C


def split(path: str) -> dict:
    return json.load(open(f"{path}/check.json"))["test_split"]


NAME = sys.argv[2] if len(sys.argv) > 2 else "J40m_sa_se4"


def c12() -> bool:
    phi = "-1.6,0,0"
    new, old = split(f"{ROOT}/C12_{NAME}/{phi}"), split(f"{ROOT}/C12_J40m_se4/{phi}")
    r, f = new["generated"]["r_precision_top3"]["mean"], new["generated"]["fid"]["mean"]
    rb, fb = old["generated"]["r_precision_top3"]["mean"], old["generated"]["fid"]["mean"]
    ok = r >= rb - 0.03 and f <= 1.25 * fb
    print(f"C' g -1.6 seeds 1 2: {NAME} R@3 {r:.3f} (shipped {rb:.3f}, bar {rb - 0.03:.3f}), FID {f:.2f} "
          f"(shipped {fb:.2f}, bar {1.25 * fb:.2f}) -> {'PASS' if ok else 'FAIL'}")
    for key in ("r_precision_top3", "fid"):
        a = [s[key] for s in new["per_seed"]["generated"]]
        b = [s[key] for s in old["per_seed"]["generated"]]
        print(f"  per seed {key}: {NAME} {['%.3f' % v for v in a]}, shipped {['%.3f' % v for v in b]}, "
              f"paired {[f'{x - y:+.3f}' for x, y in zip(a, b)]}")
        if NAME not in SEED0:
            continue
        pool_a, pool_b = (SEED0["J40m_sa_se4"][key == "fid"], *a), (SEED0["J40m_se4"][key == "fid"], *b)
        m, h = t_interval([x - y for x, y in zip(pool_a, pool_b)])
        print(f"  pooled with seed 0 (n 384, described): J40m_sa {sum(pool_a) / 3:.3f}, shipped {sum(pool_b) / 3:.3f}, "
              f"paired {m:+.3f} +- {h:.3f} (Student-t 95 %, 3 replications)")
    return ok


def cplus() -> bool:
    g = split(f"{ROOT}/C_{NAME}/-9.81,10,0")["generated"]
    r, f = g["r_precision_top3"]["mean"], g["fid"]["mean"]
    ok = r >= 0.836 - 0.03 and f <= 1.25 * 2.95
    print(f"C+ w_x +10 N seed 0: {NAME} R@3 {r:.3f} (bar 0.806), FID {f:.2f} (bar 3.69) -> {'PASS' if ok else 'FAIL'}")
    return ok


if __name__ == "__main__":
    sys.exit(0 if {"C12": c12, "CPLUS": cplus}[sys.argv[1]]() else 1)
