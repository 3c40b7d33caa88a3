"""Rule 36's stage-A verdict for one model-check folder: python stage_a_pass.py DIR (prints the figures and PASS/FAIL;
exit status 0 on a pass). Rise >= 77 of 96; gen/sim apex and flight sizes each in [0.5, 1.5]; wind >= 60 of 64;
runs at g -1.6: never touching 0, gliding <= 1."""
from __future__ import annotations

import json
import sys
from pathlib import Path


def verdict(folder: Path) -> list[str]:
    """The failed criteria (empty: pass)."""
    r = json.loads((folder / "check.json").read_text())["response"]
    g, runs, w = r["gravity"], r["gravity_runs"], r["wind"]
    size = [g["ratios"][k]["median_ratio"] for k in ("apex_gain_m", "flight_s")]
    fails = []
    if g["rise_both"] < 77:
        fails.append(f"rise {g['rise_both']} < 77")
    for name, s in zip(("apex", "flight"), size):
        if not 0.5 <= s <= 1.5:
            fails.append(f"{name} size {s:.2f} outside [0.5, 1.5]")
    if w["downwind"] < 60:
        fails.append(f"wind {w['downwind']} < 60")
    if runs["never_touch"]["low_g"] > 0:
        fails.append(f"runs never touching {runs['never_touch']['low_g']}")
    if runs.get("glides", {}).get("low_g", 0) > 1:
        fails.append(f"runs gliding {runs['glides']['low_g']}")
    print(folder.name, f"rise {g['rise_both']}/{g['n']} sizes {size[0]:.2f}/{size[1]:.2f} wind {w['downwind']}/{w['n']}",
          "PASS" if not fails else "FAIL: " + "; ".join(fails))
    return fails


if __name__ == "__main__":
    sys.exit(1 if verdict(Path(sys.argv[1])) else 0)
