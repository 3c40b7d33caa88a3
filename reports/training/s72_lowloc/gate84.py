"""Rule 84's gate on an env_probe.py log: python gate84.py PROBE_LOG RULE SPEED_BAR.
Pass when wind >= 60 of 64 walks drift downwind, the median apex change under g -1.6 >= 0.32 m, at most 4 of the 64
walks and runs under g -1.6 glide (simdiff.motion.metrics.glides) and their median root speed ratio (g -1.6 over Earth)
>= SPEED_BAR (rule 84: half the simulator's ratio for the run and walk replays, lowloc_stats.py); prints one line
ending in 'gate PASS' or 'gate FAIL'. Rule 68's gate (../s61_distill/gate68.py) asked the ratio >= 0.80 and no glide
count."""
import json
import sys

rows = [json.loads(line) for line in open(sys.argv[1]) if line.startswith("{")]
if not rows:
    sys.exit(f"{sys.argv[1]}: no result line (a JSON line from env_probe.py): the probe failed or did not finish")
r = rows[-1]
bar = float(sys.argv[3])
wind = sum(v["downwind"] for v in r["wind"].values())
if "glides_low_g" not in r.get("moon", {}):
    sys.exit(f"{sys.argv[1]}: no glides_low_g in its moon section (a probe made before session 71): run env_probe.py again")
apex, ratio, glide = r["gravity"]["apex_change_median_m"], r["moon"]["speed_ratio_median"], r["moon"]["glides_low_g"]
ok = wind >= 60 and apex >= 0.32 and glide <= 4 and ratio >= bar
print(f"rule {sys.argv[2]} gate: wind {wind}/64, apex change {apex:.3f} m, glides {glide}/64, speed ratio {ratio:.3f} "
      f"(bar {bar:.3f}) -> gate {'PASS' if ok else 'FAIL'}")
