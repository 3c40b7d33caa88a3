"""Rule 49's stage-B verdict (rule 46's criteria): python stage_b49.py NAME WALK_JUMPS (against B_J40m_c3).
Exit 0 on a pass."""
import sys

sys.path.insert(0, "reports/training/s53_extrapolate")
from stage_b import load  # noqa: E402

c, b, walk = load(sys.argv[1]), load("J40m_c3"), int(sys.argv[2])
fails = []
if c["fid"][0] > 0.90 * b["fid"][0]:
    fails.append(f"FID e1 {c['fid'][0]:.2f} > {0.90 * b['fid'][0]:.2f}")
if c["fid"][1] > 1.10 * b["fid"][1] and c["fid"][2] > 1.10 * b["fid"][2]:
    fails.append("FID e2 and e3 both > 1.10 x base")
if c["r3"][0] < b["r3"][0] - 0.015:
    fails.append(f"R@3 e1 {c['r3'][0]:.3f} < {b['r3'][0] - 0.015:.3f}")
if sum(c["r3"]) / 3 < sum(b["r3"]) / 3 - 0.015:
    fails.append(f"mean R@3 {sum(c['r3']) / 3:.3f} < {sum(b['r3']) / 3 - 0.015:.3f}")
if c["jumps"] < 39:
    fails.append(f"jumps {c['jumps']} < 39")
if c["slide"] > 1.0 or c["skate"] > 2 * c["gt_skate"]:
    fails.append("sliding or skate")
for k in ("walk", "run"):
    m, q1, q3 = c[k]
    if not q1 <= m <= q3:
        fails.append(f"{k} {m:.2f} outside [{q1:.2f}, {q3:.2f}]")
if walk > 3:
    fails.append(f"walk guard {walk} > 3")
print(f"{c['name']}: jumps {c['jumps']} {c['per_prompt']}, R@3 {['%.3f' % v for v in c['r3']]}, FID "
      f"{['%.2f' % v for v in c['fid']]}, sliding {c['slide']:.3f}, skate {c['skate']:.3f} (GT {c['gt_skate']:.3f}), "
      f"walk {c['walk'][0]:.2f}, run {c['run'][0]:.2f}, walk guard {walk} ->", "PASS" if not fails else "FAIL: " + "; ".join(fails))
sys.exit(1 if fails else 0)
