"""Rule 38's stage-C verdict: python stage_c.py NAME [BASE] (eval11/C_<name>/<phi>/check.json under /work/scratch/s39;
BASE default J40m_se4). At g -1.6 and at w_x +10 N: R@3 >= base's - 0.03 and FID <= 1.25 x base's (evaluator 1).
Exit status 0 on a pass, 1 on a failure."""
import json
import sys

ROOT = "/work/scratch/s39/eval11"


def figures(name: str, phi: str) -> tuple[float, float]:
    """(R@3, FID) of evaluator 1 on the val motions generated under phi."""
    g = json.load(open(f"{ROOT}/C_{name}/{phi}/check.json"))["test_split"]["generated"]
    return g["r_precision_top3"]["mean"], g["fid"]["mean"]


if __name__ == "__main__":
    name, base = sys.argv[1], sys.argv[2] if len(sys.argv) > 2 else "J40m_se4"
    fails = []
    for phi in ("-1.6,0,0", "-9.81,10,0"):
        (r, f), (rb, fb) = figures(name, phi), figures(base, phi)
        print(f"{name} phi {phi}: R@3 {r:.3f} (base {rb:.3f}, bar {rb - 0.03:.3f}), FID {f:.2f} (base {fb:.2f}, "
              f"bar {1.25 * fb:.2f})")
        fails += [f"R@3 at {phi}"] * (r < rb - 0.03) + [f"FID at {phi}"] * (f > 1.25 * fb)
    print("PASS" if not fails else "FAIL: " + ", ".join(fails))
    sys.exit(1 if fails else 0)  # session 54: run47.sh read the exit status, which was 0 on a failure before this line
