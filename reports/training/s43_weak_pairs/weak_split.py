"""Write split ``NAME`` into three augmented folders: weak-gravity twins drawn more often (session 43, rule 17).

usage: python weak_split.py WEAKG GEN WIND NAME [BASE] [W_MID] [W_LOW]

WEAKG's BASE split (default first_try) with every simulated item that is off Earth and has a kept Earth twin
listed W_MID times (g in [-5, -3) m/s^2; default 3) or W_LOW times (g in [-3, -1); default 6); the rest once.
GEN's and WIND's BASE split are copied unchanged under NAME (``--split`` names one file in every folder).
Earth items are not repeated: a repeated Earth item would be its own Earth twin (a zero-difference pair).
"""
from __future__ import annotations

import json
import sys
from pathlib import Path

from simdiff.data.humanml3d import read_split


def main(weakg: Path, gen: Path, wind: Path, name: str, base: str = "first_try", w_mid: int = 3,
         w_low: int = 6) -> None:
    env = json.loads((weakg / "env.json").read_text())
    ids = read_split(weakg / f"{base}.txt")
    twinned = {env[i]["source"] for i in ids if env[i]["factor"] == "earth"}  # sources with a kept Earth item
    out: list[str] = []
    counts = {"earth": 0, "no twin": 0, "mid": 0, "low": 0}
    for i in ids:
        row = env[i]
        if row["factor"] == "earth":
            counts["earth"] += 1
            out.append(i)
            continue
        if row["source"] not in twinned:
            counts["no twin"] += 1
            out.append(i)
            continue
        low = row["env"][0] >= -3.0
        counts["low" if low else "mid"] += 1
        out.extend([i] * (w_low if low else w_mid))
    (weakg / f"{name}.txt").write_text("\n".join(out) + "\n")
    sizes = {"weakg": len(out)}
    for folder, key in ((gen, "gen"), (wind, "wind")):
        rows = read_split(folder / f"{base}.txt")
        (folder / f"{name}.txt").write_text("\n".join(rows) + "\n")
        sizes[key] = len(rows)
    total = sum(sizes.values())
    print(f"items {counts}; draws {sizes} (weak twins {100 * (counts['mid'] * w_mid + counts['low'] * w_low) / total:.0f} %"
          f" of {total})")


if __name__ == "__main__":
    a = sys.argv[1:]
    main(Path(a[0]), Path(a[1]), Path(a[2]), a[3], *(a[4:5] or []), *[int(v) for v in a[5:7]])
