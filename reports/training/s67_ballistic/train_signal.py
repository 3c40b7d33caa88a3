import json, numpy as np, sys
from pathlib import Path
from simdiff.motion.flight import flight_stats
root = Path(sys.argv[1]); env = json.loads((root/"env.json").read_text())
by = {}
for k, v in env.items():
    by.setdefault(v["source"], {})[k] = v
rows = []
for src, d in by.items():
    e = [k for k, v in d.items() if v["factor"] == "earth"]
    if not e: continue
    je = np.load(root/"new_joints"/f"{e[0]}.npy"); fe = flight_stats(je)
    if fe["flight_s"] < 0.2: continue
    for k, v in d.items():
        if v["factor"] != "gravity": continue
        j = np.load(root/"new_joints"/f"{k}.npy"); f = flight_stats(j)
        rows.append((v["env"][0], fe["apex_gain_m"], f["apex_gain_m"], fe["flight_s"], f["flight_s"], len(j)))
r = np.array(rows); print("pairs", len(r), "sources with flight")
for lo, hi in [(-2.2, -1.2), (-3.5, -2.2), (-6, -3.5), (-9, -6)]:
    m = (r[:, 0] >= lo) & (r[:, 0] < hi)
    if m.sum():
        print(f"g in [{lo},{hi}) n {m.sum()}: earth apex {np.median(r[m,1]):.3f} low apex {np.median(r[m,2]):.3f} "
              f"apex change {np.median(r[m,2]-r[m,1]):.3f} flight {np.median(r[m,3]):.2f}->{np.median(r[m,4]):.2f} len {np.median(r[m,5]):.0f}")
