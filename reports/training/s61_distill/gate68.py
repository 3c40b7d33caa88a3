"""Rule 68's gate on an env_probe.py log (also rules 69-74): python gate68.py PROBE_LOG RULE.
Pass when wind >= 60 of 64 walks drift downwind, the median apex change under g -1.6 >= 0.32 m and the median root
speed ratio (g -1.6 over Earth) of walks and runs >= 0.80; prints one line ending in 'gate PASS' or 'gate FAIL'."""
import json
import sys

r = [json.loads(line) for line in open(sys.argv[1]) if line.startswith("{")][-1]
wind = sum(v["downwind"] for v in r["wind"].values())
apex, ratio = r["gravity"]["apex_change_median_m"], r["moon"]["speed_ratio_median"]
ok = wind >= 60 and apex >= 0.32 and ratio >= 0.80
print(f"rule {sys.argv[2]} gate: wind {wind}/64, apex change {apex:.3f} m, speed ratio {ratio:.3f} -> gate {'PASS' if ok else 'FAIL'}")
