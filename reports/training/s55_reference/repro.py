"""Rule 48's evaluator check: does stage B of the shipped settings on this scratch (eval11/B_J40m_c3) print session
54's figures? Exit 0 when every figure matches to the printed digits, 1 otherwise (then the bases are re-measured)."""
import json
import sys

B = "/work/scratch/s39/eval11/B_J40m_c3/check.json"
RECORDED = {"jumps": 44, "r3": [0.820, 0.879, 0.801], "fid": [2.87, 1.55, 1.90]}  # stageB_table.md, session 54

d = json.load(open(B))
ts = d["test_split"]
evals = [ts["generated"]] + [m["generated"] for m in ts.get("more_evaluators", [])]
got = {"jumps": d["jumps"]["overall"]["jumps"], "r3": [round(e["r_precision_top3"]["mean"], 3) for e in evals],
       "fid": [round(e["fid"]["mean"], 2) for e in evals]}
same = got == RECORDED
print(f"B_J40m_c3 on this scratch: {got}; session 54: {RECORDED} -> {'reproduced' if same else 'DIFFERENT'}")
sys.exit(0 if same else 1)
