"""Per-gravity breakdown of an environment-response report.json (session 29): for each model, gravity level and
prompt, the median generated and simulated Δapex (m) against the same seed at Earth, how many of the 8 seeds rise
(> 5 mm), and the mean generated Δ flight time (s). Usage: python per_gravity.py REPORT_JSON[.xz] [...] > table.md"""
import json
import lzma
import sys

import numpy as np

print("| report | model | g (m/s²) | prompt | n | gen Δapex median | rises > 5 mm | sim Δapex median (n) | gen Δflight mean (s) |")
print("|---|---|---|---|---|---|---|---|---|")
for path in sys.argv[1:]:
    for row in json.load((lzma.open if path.endswith(".xz") else open)(path, "rt"))["rows"]:
        for g in (-1.6, -3.7, -6.0, -15.0):
            for prompt in ("a person jumps forward", "a person jumps up in place", "a person walks forward",
                           "a person runs forward"):
                eff = [e for e in row["effects"] if e["env"] == [g, 0.0, 0.0] and e["unit"].split("#")[0] == prompt]
                dg = [e["dgen"]["apex_m"] for e in eff]
                ds = [e["dsim"]["apex_m"] for e in eff if e.get("dsim")]
                sim = f"{np.median(ds):+.3f} ({len(ds)})" if ds else f"— (0)"
                print(f"| {path.split('/')[-2]} | {row['method']} | {g} | {prompt} | {len(dg)} | {np.median(dg):+.3f} | "
                      f"{sum(x > 0.005 for x in dg)}/{len(dg)} | {sim} | {np.mean([e['dgen']['flight_s'] for e in eff]):+.3f} |")
