"""Rule 51's stage-T verdict: python t51.py NEW [OLD] (eval11 folders; OLD = the shipped report's copy). Exit 0 = ship."""
import json
import sys

S = "/work/scratch/s39/eval11"
NEW, OLD = sys.argv[1], sys.argv[2] if len(sys.argv) > 2 else "T_3_J40m_se4_fb3_c53"
new, old = (json.load(open(f"{S}/{n}/check.json")) for n in (NEW, OLD))


def fids(rep: dict) -> list[float]:
    ts = rep["test_split"]
    return [ts["generated"]["fid"]["mean"]] + [m["generated"]["fid"]["mean"] for m in ts["more_evaluators"]]


fails = []
by_new = {v["check"]: v for v in new["verdicts"]}
for v in old["verdicts"]:
    if v["passed"] and not by_new[v["check"]]["passed"]:
        fails.append(f"{v['check']} no longer passes ({by_new[v['check']]['value']})")
for i, (a, b) in enumerate(zip(fids(new), fids(old)), 1):
    print(f"FID evaluator {i}: {a:.3f} (shipped {b:.3f})")
    if a > b:
        fails.append(f"FID e{i} {a:.3f} > {b:.3f}")
r, rb = (rep["test_split"]["generated"]["r_precision_top3"]["mean"] for rep in (new, old))
print(f"R@3 evaluator 1: {r:.3f} (shipped {rb:.3f}, bar {rb - 0.015:.3f})")
if r < rb - 0.015:
    fails.append(f"R@3 e1 {r:.3f} < {rb - 0.015:.3f}")
jumps = round(new["figures"]["jump_fraction"] * 96)
print(f"jumps {jumps} of 96 (shipped {round(old['figures']['jump_fraction'] * 96)}, bar 34)")
if jumps < 34:
    fails.append(f"jumps {jumps} < 34")
print("SHIP" if not fails else "DO NOT SHIP: " + "; ".join(fails))
sys.exit(1 if fails else 0)
