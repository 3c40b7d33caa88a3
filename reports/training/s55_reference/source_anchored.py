"""Session 55 (rule 50, measuring before any plumbing): run a script (simdiff's CLI, a probe) with the adapters'
training targets anchored on the source clip.

usage: SOURCE_ANCHORED=CORPUS python reports/training/s55_reference/source_anchored.py -m simdiff train adapters ...
With it, every simulated item of a simulator-augmented corpus (simdiff.data.augment.dataset.AugmentedHumanML3D) loads
    x_source + (x_sim(phi) - x_sim(Earth))                    (frames x 263 HumanML3D features, un-normalised)
instead of x_sim(phi): the source clip's frames (CORPUS, the corpus it was augmented from) plus the simulator's change
between the item and its Earth twin (same source clip, frames and captions). An Earth item loads the source clip
itself. The four foot-contact channels are clipped to [0, 1]. Where the item, its Earth twin and the source frames
differ in length (a re-timed rollout) or the Earth twin was not kept, the item loads as before (x_sim(phi)). Measurement
M1 (this folder's README): the tracker's Earth replays lose 0.18-0.28 R@3 against ground truth and sit at FID 14-24;
these targets keep the simulator's answer to phi without its answer to Earth.
Prints, once per dataset, how many items got anchored targets."""
import os
import runpy
import sys
from pathlib import Path

import numpy as np

import simdiff.data.augment.dataset as D

SOURCE = Path(os.environ["SOURCE_ANCHORED"])
_init = D.AugmentedHumanML3D.__init__
CONTACTS = slice(259, 263)


def _anchored(self, *args, **kwargs):
    _init(self, *args, **kwargs)
    sim, plain = self.sim, self.sim.load_motion
    earth_twin = {}
    for i, it in enumerate(sim.items):
        earth, _ = self._twins[i]
        earth_twin[it.name] = None if self._is_earth(i) else (sim.items[earth[0]] if earth else False)
    counts = {"anchored": 0, "plain": 0}

    def load(item):
        x = plain(item)
        twin = earth_twin.get(item.name, False)
        if twin is False:  # no Earth twin kept: the simulated target as before
            return x
        src = np.load(SOURCE / "new_joint_vecs" / f"{self.env_table[item.clip_id]['source']}.npy")[item.start:item.stop]
        src = src.astype(np.float32)
        if twin is None:  # the Earth item itself: the source clip
            return src if len(src) == len(x) else x
        e = plain(twin)
        if not len(src) == len(x) == len(e):
            return x
        out = src + (x - e)
        out[:, CONTACTS] = np.clip(out[:, CONTACTS], 0.0, 1.0)
        return out

    sim.load_motion = load
    usable = 0
    for it in sim.items:
        twin = earth_twin[it.name]
        if twin is False:
            continue
        n_src = int(np.load(SOURCE / "new_joint_vecs" / f"{self.env_table[it.clip_id]['source']}.npy",
                            mmap_mode="r")[it.start:it.stop].shape[0])
        n_twin = it.length if twin is None else twin.length
        usable += int(n_src == it.length == n_twin)
    print(f"source_anchored: {usable} of {len(sim.items)} simulated items anchored on {SOURCE}", file=sys.stderr,
          flush=True)


D.AugmentedHumanML3D.__init__ = _anchored
if sys.argv[1] == "-m":
    sys.argv = sys.argv[2:]
    runpy.run_module(sys.argv[0], run_name="__main__", alter_sys=True)
else:
    sys.argv = sys.argv[1:]
    runpy.run_path(sys.argv[0], run_name="__main__")
