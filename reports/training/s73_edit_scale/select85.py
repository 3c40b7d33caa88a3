"""Rules 85 and 86's choice of sampling from glides.log and sizes.log (rule85.txt, rule86.txt).
python select85.py FOLDER [--glides-ok MODEL] [--prefix P | --only P]: with --glides-ok, exit 0 when MODEL's last glide line
passes (<= 1 of 16 runs gliding at g -1.6, none never touching). Else prints each screened model folder's (those whose
path starts with P) sizes and margin and the choice line ('choice: s_e X margin M' or, with --prefix, 'choice: FOLDER
margin M'; 'choice: none')."""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path


def lines(path: Path) -> dict[str, dict]:
    """Last JSON line per model folder."""
    out: dict[str, dict] = {}
    if path.exists():
        for line in path.read_text().splitlines():
            if line.startswith("{"):
                d = json.loads(line)
                out[d["model"]] = d
    return out


def glides_ok(d: dict) -> bool:
    return d["low_g"]["glides"] <= 1 and d["low_g"]["never_touch"] == 0


ap = argparse.ArgumentParser()
ap.add_argument("folder", type=Path)
ap.add_argument("--glides-ok")
ap.add_argument("--prefix", default="")
ap.add_argument("--only", default="", help="screen only the model folders starting with this, labelled by s_e")
a = ap.parse_args()
glides, sizes = lines(a.folder / "glides.log"), lines(a.folder / "sizes.log")
if a.glides_ok:
    sys.exit(0 if a.glides_ok in glides and glides_ok(glides[a.glides_ok]) else 1)
best = None
for model, g in glides.items():
    if not model.startswith(a.prefix) or not model.startswith(a.only):
        continue
    se = g["sampling"]["env_guidance"]
    if a.prefix:
        se = f"{se} edit_t {g['sampling']['edit_t']}"
    s = sizes.get(model)
    if not glides_ok(g) or s is None:
        print(f"s_e {se}: glides {g['low_g']['glides']}/16, never touching {g['low_g']['never_touch']}: out")
        continue
    ap_, fl = s["apex_gain_m_size"], s["flight_s_size"]
    margin = min(ap_ - 0.5, 1.5 - ap_, fl - 0.5, 1.5 - fl)
    print(f"s_e {se}: glides {g['low_g']['glides']}/16, rise {s['rise_both']}/48, apex size {ap_:.3f} "
          f"{s['apex_gain_m_ci95']}, flight size {fl:.3f} {s['flight_s_ci95']}: margin {margin:.3f}")
    if margin >= 0.10 and (best is None or margin > best[1]):
        best = (model if a.prefix else f"s_e {se}", margin)
print("choice: none" if best is None else f"choice: {best[0]} margin {best[1]:.3f}")
