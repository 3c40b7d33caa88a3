"""Reduced-gravity pairs made without the simulator (``simdiff data reduced-gravity``).

Where a rollout cannot make the data: under g −1 … −4 most replays of runs and jumps fall (the tracker keeps Earth's
stance timing while the flight lasts longer), so the simulator's low-gravity packs hold few flights. The physics of
those motions is known in closed form, so they are made from the motion itself:

* **jumps** (``motion_type`` jump): each flight re-timed to a ballistic one under g with the take-off kept
  (:func:`simdiff.motion.flight_retime.retime_flights`): the flight's centre of mass reads exactly g, apex and
  flight time grow by about 9.81/|g|, stance frames are the capture's. A jump whose own flights do not read within
  :data:`SOURCE_TOLERANCE` of Earth's gravity (not a free flight, or a capture glitch) is left out;
* **walks and runs**: the clip slowed by s = √(9.81/|g|) (:func:`simdiff.sim.retime.stretch`), the dynamically
  similar motion: same positions, velocities ÷ s, accelerations ÷ s², so the Froude number and the gait are kept
  and every flight's curvature is g (reduced-gravity studies: people choose their gait by Froude number).

Each source gets an Earth item (condition 0, the same construction at −9.81) and ``conditions`` items under gravity
drawn uniformly from ``gravity_range`` (seeded per clip), no wind. The folder has the layout of ``simdiff data
augment``'s (features, joints, captions, ``env.json`` with ``source``, ``train.txt``, Mean/Std, ``source_corpus.json``),
so ``simdiff train adapters --data`` reads it with the simulator's folders and makes the Earth item each item's twin.
"""

from __future__ import annotations

import zlib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from simdiff.data.augment.classes import load_motion_types
from simdiff.data.augment.pairs import load_source_joints, rollout_to_layout
from simdiff.data.writer import check_apart, cleaned_on_failure, write_bytes, write_json, write_lines, write_npy
from simdiff.errors import SimdiffError
from simdiff.motion.flight_retime import retime_flights
from simdiff.motion.gravity_readout import read_gravity
from simdiff.sim.env import EARTH_GRAVITY
from simdiff.sim.retime import stretch

JUMP_TYPES: tuple[str, ...] = ("jump",)
GAIT_TYPES: tuple[str, ...] = ("walk", "run")
SOURCE_TOLERANCE: float = 0.25
"""A jump is re-timed only when its own flights read within 25 % of −9.81 (real jumps: median −9.3)."""
MAX_ITEM_FRAMES: int = 600
"""Longest item kept (30 s at 20 fps; training crops it)."""


@dataclass(frozen=True)
class KinematicConfig:
    """Options of :func:`make_reduced_gravity`.

    Attributes:
        split: split file of the corpus whose clips are used.
        conditions: reduced-gravity items per source clip (besides its Earth item).
        gravity_range: (low, high) g_z in m/s², both negative, low < high.
        seed: base seed of the gravity draws (each clip's draw depends only on it and the clip id).
    """

    split: str = "train"
    conditions: int = 4
    gravity_range: tuple[float, float] = (-5.0, -1.0)
    seed: int = 0

    def __post_init__(self) -> None:
        lo, hi = self.gravity_range
        if not (np.isfinite(lo) and np.isfinite(hi) and lo < hi < 0.0):
            raise SimdiffError(f"gravity range must be two negative numbers, low < high, got {lo} {hi}")
        if not 1 <= self.conditions <= 64:
            raise SimdiffError(f"conditions must be 1..64, got {self.conditions}")


def transform(joints: np.ndarray, motion_type: str, gravity: float) -> np.ndarray | None:
    """(T', 22, 3) the clip under ``gravity`` by its type's rule (module docstring); None when it has none."""
    if motion_type in GAIT_TYPES:
        return stretch(joints, float(np.sqrt(abs(EARTH_GRAVITY) / abs(gravity))))
    if motion_type in JUMP_TYPES:
        reading = read_gravity(joints)
        if reading is None or abs(reading["gravity"] / EARTH_GRAVITY - 1.0) > SOURCE_TOLERANCE:
            return None
        try:
            return retime_flights(joints, gravity)
        except SimdiffError:  # a take-off that would fly longer than MAX_FLIGHT_S
            return None
    return None


def draw_gravity(clip: str, config: KinematicConfig) -> list[float]:
    """The clip's ``config.conditions`` gravities (m/s²), uniform in the range, fixed by the seed and the clip id."""
    rng = np.random.default_rng([config.seed, zlib.crc32(clip.encode())])
    lo, hi = config.gravity_range
    return [round(float(g), 3) for g in rng.uniform(lo, hi, size=config.conditions)]


def make_reduced_gravity(corpus: str | Path, out: str | Path, config: KinematicConfig,
                         progress: bool = True) -> dict[str, Any]:
    """Write the reduced-gravity folder ``out`` from ``corpus`` (module docstring); returns a summary dict."""
    from tqdm import tqdm

    from simdiff.data.humanml3d import read_split
    from simdiff.model.provenance import SOURCE_CORPUS_NAME, source_record

    corpus, out = Path(corpus), Path(out)
    if not corpus.is_dir():
        raise SimdiffError(f"{corpus}: not a corpus folder")
    check_apart(corpus, out, "--corpus", "--out")
    types = load_motion_types(corpus)
    if types is None:
        raise SimdiffError(f"{corpus}: no manifest.json (the motion types choose each clip's rule)")
    clips = [c for c in read_split(corpus / f"{config.split}.txt") if types.get(c) in JUMP_TYPES + GAIT_TYPES]
    if not clips:
        raise SimdiffError(f"{corpus}: split {config.split!r} has no clip of type {', '.join(JUMP_TYPES + GAIT_TYPES)}")
    with cleaned_on_failure(out):  # a failed or interrupted run leaves no folder it created
        env: dict[str, dict[str, Any]] = {}
        skipped: list[str] = []
        for clip in tqdm(sorted(set(clips)), desc="reduced gravity", unit="clip", disable=not progress):
            joints = load_source_joints(corpus, clip)
            gravities = [EARTH_GRAVITY, *draw_gravity(clip, config)]
            made = [transform(joints, types[clip], g) for g in gravities]
            if any(m is None or len(m) > MAX_ITEM_FRAMES for m in made):
                skipped.append(clip)
                continue
            caption = (corpus / "texts" / f"{clip}.txt").read_bytes()
            rule = "ballistic flights" if types[clip] in JUMP_TYPES else "froude"
            for index, (g, motion) in enumerate(zip(gravities, made)):
                item = f"{clip}_k{index:02d}"
                features, back = rollout_to_layout(motion)
                write_npy(out / "new_joint_vecs" / f"{item}.npy", features)
                write_npy(out / "new_joints" / f"{item}.npy", back)
                write_bytes(out / "texts" / f"{item}.txt", caption)
                env[item] = {"env": [g, 0.0, 0.0], "env_index": index, "condition": index, "factor": "gravity",
                             "source": clip, "made_by": rule}
        ids = sorted(env)
        write_lines(out / "train.txt", ids)
        write_lines(out / "all.txt", ids)
        write_json(out / "env.json", env)
        write_json(out / SOURCE_CORPUS_NAME, source_record(corpus, {r["source"] for r in env.values()}))
        for name in ("Mean.npy", "Std.npy"):
            write_bytes(out / name, (corpus / name).read_bytes())
        summary = {"items": len(ids), "sources": len({r["source"] for r in env.values()}), "skipped": len(skipped),
                   "config": {"split": config.split, "conditions": config.conditions,
                              "gravity_range": list(config.gravity_range), "seed": config.seed}}
        write_json(out / "reduced_gravity.json", summary)
    return summary
