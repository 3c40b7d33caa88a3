"""Session 58's twin measurements (numpy over first_try items): python twin_stats.py AUG...

Per augmented folder and twin-frames mode (equal / prefix): items trimmed, items anchored (source-anchored targets),
low-gravity items (g > -2.5) and how many of them have a twin, the median change of the target's apex (root height
above its median, feature 3, m) against the twin's, and over every non-Earth twin pair the median / 90th percentile of
|mean root-velocity difference| (features 1:3, per frame) -- what the drift term compares."""
import sys

import numpy as np

from simdiff.data.augment.dataset import AugmentedHumanML3D

EARTH = [-9.81, 0.0, 0.0]


def apex(x: np.ndarray) -> float:
    return float(x[:, 3].max() - np.median(x[:, 3]))


for root in sys.argv[1:]:
    for mode in ("equal", "prefix"):
        ds = AugmentedHumanML3D(root, "first_try", targets="source-anchored", twin_frames=mode)
        rng, low, apex_change, drift = np.random.default_rng(0), 0, [], []
        for i, item in enumerate(ds.sim.items):
            env = ds.env_table[item.clip_id]["env"]
            if env == EARTH:
                continue
            j = ds.twin(i, rng)
            low += env[0] > -2.5
            if j is None:
                continue
            a, b = ds.sim.load_motion(item), ds.sim.load_motion(ds.sim.items[j])
            drift.append(float(np.abs((a[:, 1:3] - b[:, 1:3]).mean(0)).max()))
            if env[0] > -2.5:
                apex_change.append(apex(a) - apex(b))
        med = f"{np.median(apex_change):+.3f} m" if apex_change else "-"
        print(f"{root.rstrip('/').split('/')[-1]} {mode}: trimmed {ds.trimmed}, anchored {ds.anchored} of "
              f"{len(ds.sim.items)}; low-g items {low}, paired {len(apex_change)}, median target apex change {med}; "
              f"twin pairs {len(drift)}, |mean root-vel diff| median {np.median(drift):.4f} p90 "
              f"{np.percentile(drift, 90):.4f}")


def raw_lengths(root: str) -> None:
    """Per non-Earth first_try replay: is its Earth replay (same source) kept, of equal or other length; and for
    g > -2.5 the apex change (pelvis height above its median, new_joints, whole replays) against the Earth replay."""
    import collections
    import json
    from pathlib import Path

    folder = Path(root)
    env = json.loads((folder / "env.json").read_text())
    ids = (folder / "first_try.txt").read_text().split()
    by = collections.defaultdict(dict)
    for i in ids:
        by[env[i]["source"]][i] = env[i]["env"]
    counts, change = collections.Counter(), {"equal": [], "other": []}
    for group in by.values():
        earth = [i for i, e in group.items() if e == EARTH]
        for i, e in group.items():
            if e == EARTH:
                continue
            if not earth:
                counts["no Earth replay kept"] += 1
                continue
            a, b = (np.load(folder / "new_joints" / f"{k}.npy")[:, 0, 1] for k in (i, earth[0]))
            kind = "equal" if len(a) == len(b) else "other"
            counts[f"{kind} length"] += 1
            if e[0] > -2.5:
                change[kind].append(float((a.max() - np.median(a)) - (b.max() - np.median(b))))
    print(f"{folder.name} raw replays: {dict(counts)}; g > -2.5: " + ", ".join(
        f"{k} length {len(v)} (median apex change {np.median(v):+.4f} m)" for k, v in change.items() if v))


for root in sys.argv[1:]:
    raw_lengths(root)
