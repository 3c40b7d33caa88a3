"""The simulator's answer for walks and runs under low gravity: python lowloc_stats.py AUG_FOLDER SOURCE_CORPUS.

Over the kept replays of AUG_FOLDER with g_z > -9 (m/s^2): the median ratio of the replay's mean horizontal root speed
to its source clip's (both from new_joints, 20 fps), the share of frames with no foot joint below 0.05 m (airborne),
the largest foot-joint height range (m) and the retime scale, with the Earth replays' figures beside. One JSON line."""
import json
import sys
from pathlib import Path

import numpy as np

from simdiff.eval.model_check.detect import root_speed as speed
from simdiff.motion.skeleton import FOOT_LEFT, FOOT_RIGHT

FEET = [*FOOT_LEFT, *FOOT_RIGHT]


def main() -> None:
    aug, src = Path(sys.argv[1]), Path(sys.argv[2])
    env = json.loads((aug / "env.json").read_text())
    kept = [line.strip() for line in (aug / "all.txt").read_text().split() if line.strip()]
    rows = {"low_g": [], "earth": []}
    for i in kept:
        e = env[i]
        j = np.load(aug / "new_joints" / f"{i}.npy")
        s = np.load(src / "new_joints" / f"{e['source']}.npy")
        feet = j[:, FEET, 1]
        rows["low_g" if e["env"][0] > -9 else "earth"].append(
            (speed(j) / max(speed(s), 1e-6), float((feet.min(axis=1) > 0.05).mean()), float(np.ptp(feet, axis=0).max()),
             float(e.get("retime_scale") or 1.0), speed(s)))
    out = {}
    for k, r in rows.items():
        a = np.array(r) if r else np.zeros((0, 5))
        moving = a[:, 4] > 0.5 if len(a) else a[:, 0] > 0
        out[k] = {"n": len(a), "n_source_moving": int(moving.sum()),
                  "speed_ratio_median": round(float(np.median(a[moving, 0])), 3) if moving.any() else None,
                  "airborne_share_median": round(float(np.median(a[:, 1])), 3) if len(a) else None,
                  "foot_lift_median_m": round(float(np.median(a[:, 2])), 3) if len(a) else None,
                  "retime_median": round(float(np.median(a[:, 3])), 3) if len(a) else None}
    print(json.dumps({"folder": str(aug), **out}))


if __name__ == "__main__":
    main()
