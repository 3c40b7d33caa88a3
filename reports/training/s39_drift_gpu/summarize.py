"""Print rule 11's figures from model_check reports: python summarize.py DIR [DIR ...] (each holds check.json)."""
import json
import sys
from pathlib import Path

KEYS = ("r_precision_top3", "fid", "sliding_own_floor", "jump_fraction", "walk_median", "run_median",
        "gravity_rise_fraction", "gravity_ratio_apex", "gravity_ratio_flight", "wind_downwind_fraction")
for d in sys.argv[1:]:
    rep = json.loads((Path(d) / "check.json").read_text())
    f = rep["figures"]
    row = {k: (round(f[k], 4) if isinstance(f.get(k), float) else f.get(k)) for k in KEYS}
    wind = (rep.get("response") or {}).get("wind")
    if wind:
        row["wind_drift_ratio"] = round(wind["median_ratio_generated_to_simulated"], 4)
        row["downwind_per_env"] = {k: f"{v['downwind']}/{v['n']}" for k, v in wind["per_env"].items()}
        g = rep["response"]["gravity"]
        row["rise"] = f"{g['rise_both']}/{g['n']}"
        row["wind"] = f"{wind['downwind']}/{wind['n']}"
    print(Path(d).name, json.dumps(row))
