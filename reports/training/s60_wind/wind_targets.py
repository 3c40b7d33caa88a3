"""Wind signal in the adapters' training targets: per wind item with an Earth twin, drift along the wind of its
target minus its Earth twin's target over their shared first frames, grouped by wind direction."""
import sys
import numpy as np
from simdiff.data.augment.dataset import AugmentedHumanML3D
from simdiff.motion.features import features_to_joints
from simdiff.eval.response import quantities

root, split = sys.argv[1], sys.argv[2] if len(sys.argv) > 2 else "first_try"
rng = np.random.default_rng(0)
for targets, mode in [("simulated", "equal"), ("source-anchored", "equal"), ("source-anchored", "overlap")]:
    ds = AugmentedHumanML3D(root, split, targets=targets, twin_frames=mode)
    groups = {}
    for i, it in enumerate(ds.sim.items):
        env = ds.env_table[it.clip_id]["env"]
        if abs(env[1]) + abs(env[2]) < 1e-9 or abs(env[0] + 9.81) > 1e-3:
            continue
        earth = ds.twin(i, rng)  # a non-Earth item's twin is its Earth twin, or None
        if earth is None:
            continue
        a, b = ds.sim.load_motion(it), ds.sim.load_motion(ds.sim.items[earth])
        n = min(len(a), len(b), 120)
        d = quantities(features_to_joints(a[:n]), env)["drift_along_wind_m"] - \
            quantities(features_to_joints(b[:n]), env)["drift_along_wind_m"]
        w = np.hypot(env[1], env[2])
        key = ("wx+" if env[1] > 0 else "wx-") if abs(env[1]) >= abs(env[2]) else ("wy+" if env[2] > 0 else "wy-")
        groups.setdefault(key, []).append((d * 10 / w, len(a) != len(b)))
    print(root.split("/")[-1], targets, mode)
    for k in sorted(groups):
        v = np.array([g[0] for g in groups[k]]); u = np.array([g[1] for g in groups[k]])
        print(f"  {k}: n {len(v)} (unequal {u.sum()}) drift/10N median {np.median(v):+.3f} downwind {np.mean(v > 0):.2f}"
              + (f"  equal-only median {np.median(v[~u]):+.3f} unequal median {np.median(v[u]):+.3f}" if u.any() and (~u).any() else ""))
