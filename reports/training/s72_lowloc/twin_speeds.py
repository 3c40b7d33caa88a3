"""Do reduced-gravity replays travel like their Earth twins over the frames training compares them on?
python twin_speeds.py (run in /work/scratch/s67; rule 79's mix, split big79, twin_frames overlap).

For every item with a twin (AugmentedHumanML3D.twin), the mean horizontal root speed (m/s, 20 fps) of item and twin over
their common first frames, from the denormalised features (root linear velocity, channels 1:3). Prints, per folder,
the median speeds and the low-g/Earth ratio of the pairs of a reduced-gravity item and its Earth twin."""
import numpy as np

from simdiff.data.augment.dataset import open_training_dataset

NAMES = ["aug_lowg", "aug_weakg", "aug_wind", "aug_gen"]


def main() -> None:
    ds = open_training_dataset(NAMES, split="big79", twin_frames="overlap")
    for name, part in zip(NAMES, ds.parts):
        low, earth = [], []
        for i in range(len(part)):
            twin = part.twin(i, np.random.default_rng(i))
            if twin is None:
                continue
            a, b = part.get(i, np.random.default_rng(0)), part.get(twin, np.random.default_rng(0))
            if not (a["env"][0] > -9 and b["env"][0] < -9):
                continue
            n = min(int(a["length"]), int(b["length"]))
            s = [float(np.linalg.norm(part.normalizer.denormalize(x["motion"][:n])[:, 1:3], axis=-1).mean() * 20)
                 for x in (a, b)]
            low.append(s[0])
            earth.append(s[1])
        if low:
            lo, ea = np.array(low), np.array(earth)
            ratio = lo / np.maximum(ea, 1e-3)
            print(f"{name}: n {len(lo)} reduced-g items with an Earth twin; median speed {np.median(lo):.2f} vs "
                  f"{np.median(ea):.2f} m/s; ratio median {np.median(ratio):.2f} "
                  f"[IQR {np.percentile(ratio, 25):.2f}, {np.percentile(ratio, 75):.2f}]")


if __name__ == "__main__":
    main()
