"""Stage-A table of rule 31 from model-check folders: python stage_a.py DIR [DIR ...] (numbers only, no torch)."""
from __future__ import annotations

import json
import sys
from pathlib import Path


def row(folder: Path) -> str:
    """One markdown row: rise, sizes, time-in-flight change, floating runs/jumps, wind."""
    r = json.loads((folder / "check.json").read_text())["response"]
    g, runs, w = r["gravity"], r["gravity_runs"], r["wind"]
    air = g["airborne_total_s"]
    size = [g["ratios"][k]["median_ratio"] for k in ("apex_gain_m", "flight_s")]
    run_air = runs["airborne_total_s"]["generated_change"]
    cells = [folder.name, f"{g['rise_both']} of {g['n']}", f"{size[0]:.2f} / {size[1]:.2f}",
             f"{air['generated_change']['median']:+.2f} / {air['simulated_change']['median']:+.2f}",
             f"{g['never_touch']['low_g']}", f"{runs['never_touch']['low_g']} of {runs['n']}",
             f"{run_air['median']:+.2f} (n {run_air['n']})", f"{w['downwind']} of {w['n']}",
             f"{w['median_ratio_generated_to_simulated']:.2f}",
             f"{g.get('glides', {}).get('low_g', '—')} / {runs.get('glides', {}).get('low_g', '—')}"]
    return "| " + " | ".join(cells) + " |"


if __name__ == "__main__":
    print("| run | jump rise | gen ÷ sim apex / flight | jumps' time in flight change gen / sim (s) | jumps never touching at −1.6 "
          "| runs never touching at −1.6 | runs' time in flight change (gen) | wind downwind | wind drift gen ÷ sim "
          "| gliding at −1.6: jumps / runs |")
    print("|" + "---|" * 10)
    for arg in sys.argv[1:]:
        print(row(Path(arg)))
