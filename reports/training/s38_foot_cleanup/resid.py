"""Where the sliding left after the lock comes from: python resid.py CACHE_DIR (lockvar.py's cache of unlocked samples).
Bins the own-floor sliding (mm/frame, pooled as the metric) by the lowest joint's contact channels and its step size."""
import sys
import torch, numpy as np, glob
from simdiff.motion.foot_lock import lock_feet, CONTACT_JOINTS
from simdiff.motion.features import features_to_joints, SLICES
from simdiff.motion.metrics import OWN_FLOOR_PERCENTILE
fs = [torch.load(p) for p in sorted(glob.glob(sys.argv[1] + "/*.pt"))]
T = max(x.shape[1] for x in fs); f = torch.cat([torch.nn.functional.pad(x, (0, 0, 0, T - x.shape[1])) for x in fs])
# lengths: infer from zero padding? features were masked by mask -> rows of zeros after length
lens = torch.tensor([int((x.abs().sum(-1) > 0).sum()) for x in f])
lk = lock_feet(f, lens, 1.0)
j = features_to_joints(lk.double()).numpy()
tot = 0; bins = {}; npairs = 0
for b in range(len(f)):
    L = int(lens[b]); a = j[b, :L]
    low = a[..., 1].min(-1); floor = np.percentile(low, OWN_FLOOR_PERCENTILE); a = a.copy(); a[..., 1] -= floor
    idx = a[..., 1].argmin(-1)
    ch = lk[b, :L, SLICES["contacts"]].numpy() > 0.5
    for t in range(L - 1):
        c = idx[t]; npairs += 1
        if a[t, c, 1] <= 0.005 and a[t + 1, c, 1] <= 0.005:
            s = np.hypot(*(a[t + 1, c, [0, 2]] - a[t, c, [0, 2]])) * 1000
            if s == 0: continue
            jn = list(CONTACT_JOINTS).index(c) if c in CONTACT_JOINTS else -1
            chan = "nofoot" if jn < 0 else ("chan_on" if ch[t, jn] and ch[t + 1, jn] else "chan_off")
            sp = "slow<10mm" if s < 10 else ("mid<25mm" if s < 25 else "fast>=25mm")
            k = (chan, sp); bins[k] = bins.get(k, 0) + s; tot += s
print("total mm/frame", tot / npairs)
for k, v in sorted(bins.items(), key=lambda kv: -kv[1]): print(k, round(v / npairs, 3))
