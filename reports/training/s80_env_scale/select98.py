"""Rule 98's choice of sampling (rule98.txt) from glides.log and sizes.log in FOLDER.
python select98.py FOLDER [--glides-ok MODEL]: with --glides-ok, exit 0 when MODEL's last glide line passes (<= 1 of 16
low-g runs gliding, none never touching, low-g / Earth median pelvis speed >= 0.209). Else prints each screened folder's
glides, speed ratio, sizes and margin, then 'choice: FOLDER margin M' or 'choice: none'."""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

SPEED_BAR = 0.209


def lines(path: Path) -> dict[str, dict]:
    """Last JSON line per model folder."""
    out: dict[str, dict] = {}
    if path.exists():
        for line in path.read_text().splitlines():
            if line.startswith("{"):
                d = json.loads(line)
                out[d["model"]] = d
    return out


def speed_ratio(g: dict) -> float:
    return g["low_g"]["pelvis_speed_median"] / g["earth"]["pelvis_speed_median"]


def glides_ok(g: dict) -> bool:
    return g["low_g"]["glides"] <= 1 and g["low_g"]["never_touch"] == 0 and speed_ratio(g) >= SPEED_BAR


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("folder", type=Path)
    ap.add_argument("--glides-ok")
    a = ap.parse_args()
    glides, sizes = lines(a.folder / "glides.log"), lines(a.folder / "sizes.log")
    if a.glides_ok:
        sys.exit(0 if a.glides_ok in glides and glides_ok(glides[a.glides_ok]) else 1)
    best = None
    for model, g in sorted(glides.items()):
        head = (f"{model}: glides {g['low_g']['glides']}/16, never touching {g['low_g']['never_touch']}, "
                f"speed ratio {speed_ratio(g):.3f}")
        s = sizes.get(model)
        if not glides_ok(g) or s is None:
            print(head + ": out")
            continue
        ap_, fl = s["apex_gain_m_size"], s["flight_s_size"]
        margin = min(ap_ - 0.5, 1.5 - ap_, fl - 0.5, 1.5 - fl)
        print(f"{head}, rise {s['rise_both']}/48, apex size {ap_:.3f} {s['apex_gain_m_ci95']}, flight size {fl:.3f} "
              f"{s['flight_s_ci95']}: margin {margin:.3f}")
        if margin >= 0.10 and (best is None or margin > best[1]):
            best = (model, margin)
    print("choice: none" if best is None else f"choice: {best[0]} margin {best[1]:.3f}")


if __name__ == "__main__":
    main()
