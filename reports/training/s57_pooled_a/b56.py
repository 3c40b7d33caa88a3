"""Rule 56's stage-B verdict: python b56.py NAME WALK_JUMPS (rule 36's stage-B criteria against B_J40m_c3, plus the walk
guard: at most 3 of 64 walking samples jump). Run from the repository root. Exit 0 on a pass."""
import sys

sys.path.insert(0, "reports/training/s53_extrapolate")
from stage_b import load, verdict  # noqa: E402

c, walk = load(sys.argv[1]), int(sys.argv[2])
fails = verdict(c, load("J40m_c3")) + ([f"walk guard {walk} > 3"] if walk > 3 else [])
print(f"{c['name']}: jumps {c['jumps']} {c['per_prompt']}, R@3 {['%.3f' % v for v in c['r3']]}, FID "
      f"{['%.2f' % v for v in c['fid']]}, walk {c['walk'][0]:.2f}, run {c['run'][0]:.2f}, walk guard {walk} ->",
      "PASS" if not fails else "FAIL: " + "; ".join(fails))
sys.exit(1 if fails else 0)
