"""Session 51: do the simulator-replayed training clips float? For each augmentation set, per motion type of the
source clip and per gravity band: clips whose lowest joint never comes within 0.10 m of y = 0
(simdiff.motion.metrics.never_touches) and the change of time in flight (all flights, simdiff.motion.flight) against
the same source's Earth replay.  usage: python aug_floor.py CORPUS AUG_DIR... (env SPLIT: the list of kept clips
read, default first_try)"""
import json
import os
import sys
from collections import defaultdict
from pathlib import Path

import numpy as np

from simdiff.motion.flight import flight_stats
from simdiff.motion.metrics import never_touches

corpus = Path(sys.argv[1])
types = {c["id"]: c["motion_type"] for c in json.loads((corpus / "manifest.json").read_text())["clips"]}
for aug in map(Path, sys.argv[2:]):
    env = json.loads((aug / "env.json").read_text())
    ids = (aug / f"{os.environ.get('SPLIT', 'first_try')}.txt").read_text().split()
    earth_flight, rows = {}, []
    for i in ids:
        e = env.get(i)
        f = aug / "new_joints" / f"{i}.npy"
        if e is None or not f.is_file():
            continue
        j = np.load(f)
        if len(j) < 2:
            continue
        src = e["source"]
        kind = types.get(src.lstrip("M"), types.get(src, "?"))
        g = e["env"][0]
        fl = flight_stats(j)["flight_total_s"]
        if e["factor"] == "earth":
            earth_flight[src] = fl
        rows.append((src, kind, g, e["factor"], bool(never_touches(j)[0]), fl, len(j) / 20))
    table = defaultdict(list)
    for src, kind, g, factor, never, fl, secs in rows:
        if factor == "wind":
            continue
        band = "earth" if factor == "earth" else "g > -3" if g > -3 else "g <= -3"
        d = fl - earth_flight[src] if src in earth_flight else np.nan
        table[(kind, band)].append((never, d, secs))
    print(f"== {aug.name}: {len(rows)} clips")
    for (kind, band), v in sorted(table.items()):
        never = sum(x[0] for x in v)
        d = [x[1] for x in v if np.isfinite(x[1])]
        print(f"{kind:>10} {band:>8}: n {len(v):4d}  never touch {never:3d}  flight change median "
              f"{np.median(d) if d else float('nan'):+.2f} s  clip median {np.median([x[2] for x in v]):.1f} s")
