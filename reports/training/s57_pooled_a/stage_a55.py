"""Rule 55's stage-A verdict for one model-check folder of any size: python stage_a55.py DIR (exit 0 on a pass).

Rule 36's criteria with its counts turned into the same fractions, so a run over 4 seeds (n 192 jump pairs, 128 wind
walks, 32 low-gravity runs) is judged as two runs of 2 seeds would be: rise >= 77/96 of the jump pairs; generated /
simulated apex-gain and flight-time sizes each in [0.5, 1.5]; wind >= 60/64 of the walks downwind; runs at g -1.6 never
touching 0 and gliding <= 1 per 16 runs."""
from __future__ import annotations

import json
import math
import sys
from pathlib import Path


def verdict(folder: Path) -> list[str]:
    """The failed criteria (empty: pass); prints one summary line."""
    r = json.loads((folder / "check.json").read_text())["response"]
    g, runs, w = r["gravity"], r["gravity_runs"], r["wind"]
    size = [g["ratios"][k]["median_ratio"] for k in ("apex_gain_m", "flight_s")]
    ci = [g["ratios"][k]["ci95"] for k in ("apex_gain_m", "flight_s")]
    rise_bar, wind_bar = math.ceil(g["n"] * 77 / 96), math.ceil(w["n"] * 60 / 64)
    glide_bar = runs["n"] // 16
    fails = []
    if g["rise_both"] < rise_bar:
        fails.append(f"rise {g['rise_both']} < {rise_bar}")
    for name, s in zip(("apex", "flight"), size):
        if not 0.5 <= s <= 1.5:
            fails.append(f"{name} size {s:.2f} outside [0.5, 1.5]")
    if w["downwind"] < wind_bar:
        fails.append(f"wind {w['downwind']} < {wind_bar}")
    if runs["never_touch"]["low_g"] > 0:
        fails.append(f"runs never touching {runs['never_touch']['low_g']}")
    if runs.get("glides", {}).get("low_g", 0) > glide_bar:
        fails.append(f"runs gliding {runs['glides']['low_g']} > {glide_bar}")
    print(folder.name, f"rise {g['rise_both']}/{g['n']} (bar {rise_bar})",
          f"sizes {size[0]:.2f} [{ci[0][0]:.2f}, {ci[0][1]:.2f}] / {size[1]:.2f} [{ci[1][0]:.2f}, {ci[1][1]:.2f}]",
          f"(n {g['ratios']['apex_gain_m']['n_ratio']} / {g['ratios']['flight_s']['n_ratio']})",
          f"wind {w['downwind']}/{w['n']} (bar {wind_bar})", "PASS" if not fails else "FAIL: " + "; ".join(fails))
    return fails


if __name__ == "__main__":
    sys.exit(1 if verdict(Path(sys.argv[1])) else 0)
