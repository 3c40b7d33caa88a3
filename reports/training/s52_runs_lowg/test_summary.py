"""Session 52: rule 33's test run against the shipped report's run (T_3_J40m, s_e 2, cleanup 2): verdicts, R@3 / FID
under evaluators 1-3 (paired per seed, Student-t 95 % over the 5 seeds) and the gravity figures.
Usage: python test_summary.py NEW [OLD] [EVAL11_DIR]"""
import json
import sys

from simdiff.eval.stats import t_interval

NEW = sys.argv[1]
OLD = sys.argv[2] if len(sys.argv) > 2 else "T_3_J40m"
S = sys.argv[3] if len(sys.argv) > 3 else "/work/scratch/s39/eval11"
new, old = (json.load(open(f"{S}/{n}/check.json")) for n in (NEW, OLD))


def per_seed(report: dict, which: int) -> list[dict]:
    ts = report["test_split"]
    return ts["per_seed"]["generated"] if which == 0 else ts["more_evaluators"][which - 1]["per_seed"]["generated"]


print(f"{NEW} vs {OLD}")
by_old = {v["check"]: v for v in old["verdicts"]}
for v in new["verdicts"]:
    o = by_old.get(v["check"], {})
    print(f"  {v['check']:16s} {str(v['value'])[:44]:46s} {v['passed']!s:5s} (was {str(o.get('value'))[:44]}, {o.get('passed')})")
for which in range(3):
    for key in ("r_precision_top3", "fid"):
        a = [r[key] for r in per_seed(new, which)]
        b = [r[key] for r in per_seed(old, which)]
        m, h = t_interval([x - y for x, y in zip(a, b)])
        print(f"  evaluator {which + 1} {key}: {sum(a) / 5:.3f} vs {sum(b) / 5:.3f}, paired {m:+.3f} ± {h:.3f}")
for part in ("gravity", "gravity_runs"):
    g = new["response"][part]
    print(f"  {part}: rise {g['rise_both']} of {g['n']}, never touch {g['never_touch']['low_g']}, "
          f"glides {g.get('glides', {}).get('low_g')}, sizes {g['ratios']['apex_gain_m']['median_ratio']:.2f} / "
          f"{g['ratios']['flight_s']['median_ratio']:.2f} (n {g['ratios']['apex_gain_m']['n_ratio']}), time in flight "
          f"change gen {g['airborne_total_s']['generated_change']['median']:+.2f} sim "
          f"{g['airborne_total_s']['simulated_change']['median']:+.2f}, rollouts {g['rollouts']}")
w = new["response"]["wind"]
print(f"  wind: {w['downwind']} of {w['n']} downwind, gen / sim drift {w['median_ratio_generated_to_simulated']:.2f}, "
      f"glides {[v.get('glides') for v in w['per_env'].values()]}")
