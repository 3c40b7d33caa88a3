import json, numpy as np, sys
from pathlib import Path
from simdiff.motion.flight import flight_stats
for root in map(Path, sys.argv[1:]):
    env = json.loads((root/"env.json").read_text()); by = {}
    for k, v in env.items(): by.setdefault(v["source"], {})[k] = v
    rows = []
    for src, d in by.items():
        e = [k for k, v in d.items() if v["factor"] == "earth"]
        if not e: continue
        fe = flight_stats(np.load(root/"new_joints"/f"{e[0]}.npy"))
        for k, v in d.items():
            if v["factor"] == "gravity" and v["env"][0] < -0.5 and v["env"][0] >= -2.5:
                f = flight_stats(np.load(root/"new_joints"/f"{k}.npy"))
                rows.append((v["env"][0], fe["apex_gain_m"], f["apex_gain_m"], fe["flight_s"], f["flight_s"]))
    r = np.array(rows); print(root.name, "low-g pairs with an Earth twin:", len(r), "g range", r[:,0].min(), r[:,0].max())
    for lo, hi in [(0, 0.1), (0.1, 0.25), (0.25, 0.4), (0.4, 2)]:
        m = (r[:, 1] >= lo) & (r[:, 1] < hi)
        if m.sum(): print(f"  earth apex [{lo},{hi}) n {m.sum()}: low-g apex median {np.median(r[m,2]):.3f} change {np.median(r[m,2]-r[m,1]):.3f} flight {np.median(r[m,3]):.2f}->{np.median(r[m,4]):.2f}")
