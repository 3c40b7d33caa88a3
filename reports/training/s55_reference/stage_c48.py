"""Rule 48's stage-C verdict: python stage_c48.py NAME. Bases: eval11/C_J40m_se4 when this scratch has it (re-measured),
else session 54's recorded figures (rule 48: when the rebuilt scratch reproduced stage B). Exit 0 on a pass."""
import json
import os
import sys

ROOT = "/work/scratch/s39/eval11"
RECORDED = {"-1.6,0,0": (0.812, 2.33), "-9.81,10,0": (0.836, 2.95)}  # C_J40m_se4, rule46_outcome.txt (session 54)


def figures(name: str, phi: str) -> tuple[float, float]:
    """(R@3, FID) of evaluator 1 on the val motions generated under phi."""
    g = json.load(open(f"{ROOT}/C_{name}/{phi}/check.json"))["test_split"]["generated"]
    return g["r_precision_top3"]["mean"], g["fid"]["mean"]


if __name__ == "__main__":
    name, fails = sys.argv[1], []
    measured = os.path.exists(f"{ROOT}/C_J40m_se4/-1.6,0,0/check.json")
    for phi in RECORDED:
        (r, f), (rb, fb) = figures(name, phi), (figures("J40m_se4", phi) if measured else RECORDED[phi])
        print(f"{name} phi {phi}: R@3 {r:.3f} (base {rb:.3f}{'' if measured else ' recorded'}, bar {rb - 0.03:.3f}), "
              f"FID {f:.2f} (base {fb:.2f}, bar {1.25 * fb:.2f})")
        fails += [f"R@3 at {phi}"] * (r < rb - 0.03) + [f"FID at {phi}"] * (f > 1.25 * fb)
    print("PASS" if not fails else "FAIL: " + ", ".join(fails))
    sys.exit(1 if fails else 0)
