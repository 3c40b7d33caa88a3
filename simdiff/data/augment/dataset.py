"""Training items from a simulator-augmented corpus, labelled with φ for ``simdiff train adapters``.

Items are HumanML3D items (see :class:`simdiff.data.humanml3d.HumanML3D`) plus

* ``env``: (3,) float32 φ = (g_z m/s², w_x N, w_y N) of the condition the clip was replayed in;
* ``env_index``: int, the categorical label (binary: 1 simulated, 0 source; random: condition index).

``source`` optionally mixes in the original (kinematic) clips of the source corpus with
``env_index`` 0 and ``env`` = Earth (−9.81, 0, 0): the binary setting's second class.
"""

from __future__ import annotations

import dataclasses
import json
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np

from simdiff.data.augment.anchored import TARGETS, SourceAnchoredLoader, source_corpus
from simdiff.data.humanml3d import HumanML3D, Item
from simdiff.errors import SimdiffError
from simdiff.motion.normalize import Normalizer
from simdiff.sim.env import EARTH_GRAVITY

ENV_FILE = "env.json"
SOURCE_INDEX: int = 0
"""``env_index`` of source (non-simulated) clips."""
TWIN_FRAMES: tuple[str, ...] = ("equal", "prefix", "overlap")
"""How replays of one source clip are made twins: ``equal`` frames only, trimmed to their common ``prefix``, or
kept whole and compared where they ``overlap``."""


def read_env_table(root: str | Path) -> dict[str, dict[str, Any]]:
    """``root/env.json`` as {clip id: {env, env_index, ...}}."""
    path = Path(root) / ENV_FILE
    if not path.is_file():
        raise SimdiffError(f"{path}: missing (not a simulator-augmented corpus; run simdiff data augment)")
    try:
        table = json.loads(path.read_text(encoding="utf-8"))
    except json.JSONDecodeError as exc:
        raise SimdiffError(f"{path}: invalid JSON ({exc.msg}, line {exc.lineno})") from None
    for key, row in table.items():
        if len(row.get("env", [])) != 3 or "env_index" not in row:
            raise SimdiffError(f"{path}: entry {key!r} needs 'env' (3 numbers) and 'env_index'")
    return table


class AugmentedHumanML3D:
    """Simulator-augmented clips (and optionally the source clips) with φ labels.

    Args:
        root: the augmented corpus (``simdiff data augment --out``).
        split: split file of ``root`` (``train`` = every kept pair).
        source: the source corpus to mix in with ``env_index`` 0 (None: simulated clips only).
        source_split: split of ``source`` to mix in.
        normalizer: default ``root``'s Mean/Std (copied from the source corpus).
        unit_length, seed: as :class:`HumanML3D`.
        targets: ``"simulated"`` (the replays), ``"source-anchored"`` or ``"source-anchored-pairs"`` (see
            :mod:`simdiff.data.augment.anchored`; :attr:`anchored` counts the simulated items that get one).
        anchor_corpus: the source corpus for source-anchored targets (default: ``root/source_corpus.json``'s path).
        twin_frames: ``"equal"``: items of one source clip, start and captions are twins only when their replays
            have the same frames. ``"prefix"``: such items are all trimmed to their shortest replay's frames and
            are twins. A low-gravity rollout is longer than its Earth twin (the flight clock waits while the body
            flies longer: :mod:`simdiff.sim.rollout`), so under ``"equal"`` the replays that fly longer have no twin
            and the paired loss sees mostly replays that did not change (measured on a jump augmentation: 116 of
            712 low-gravity items had a twin, median apex change 0.000 m; the 596 others +0.48 m). The trim keeps
            the frames both replays share from the start, where they track the same reference frames until the
            first flight. ``"overlap"``: such items are twins and keep their own frames; every crop starts at the
            item's first frame, so twins are aligned and the paired loss compares the frames they share
            (:func:`simdiff.diffusion.losses.twin_difference_mse` masks to them), while a longer low-gravity replay
            keeps its whole flight and landing as a target (source-anchored:
            :func:`simdiff.data.augment.anchored.anchor_overlap`). :attr:`unequal` counts the items with a twin of
            another length.
    """

    def __init__(self, root: str | Path, split: str = "train", source: str | Path | None = None,
                 source_split: str = "train", normalizer: Normalizer | None = None, unit_length: int = 4,
                 seed: int = 0, targets: str = "simulated", anchor_corpus: str | Path | None = None,
                 twin_frames: str = "equal") -> None:
        if targets not in TARGETS:
            raise SimdiffError(f"unknown targets {targets!r} (choose from {', '.join(TARGETS)})")
        if twin_frames not in TWIN_FRAMES:
            raise SimdiffError(f"unknown twin frames {twin_frames!r} (choose from {', '.join(TWIN_FRAMES)})")
        self.env_table = read_env_table(root)
        self.sim = HumanML3D(root, split, normalizer=normalizer, unit_length=unit_length, seed=seed)
        self.normalizer = self.sim.normalizer
        missing = [it.clip_id for it in self.sim.items if it.clip_id not in self.env_table]
        if missing:
            raise SimdiffError(f"{Path(root) / ENV_FILE}: no φ for clip {missing[0]!r}")
        self.twin_frames = twin_frames
        self.trimmed = self._trim_to_common_prefix() if twin_frames == "prefix" else 0
        if twin_frames == "overlap":
            self.sim.random_offset = False
        self.source = None
        if source is not None:
            self.source = HumanML3D(source, source_split, normalizer=self.normalizer, unit_length=unit_length,
                                    seed=seed + 1)
        self._twins = self._twin_groups()
        self.unequal = sum(any(self.sim.items[j].length != self.sim.items[i].length for j in earth + other)
                           for i, (earth, other) in self._twins.items())
        self.targets, self.anchored = targets, 0
        if targets != "simulated":
            lone_earth = -1 if targets == "source-anchored" else None  # an Earth item without φ-twins

            def earth_twin_of(i: int) -> int | None:
                earth, other = self._twins[i]
                if self._is_earth(i):
                    return -1 if other else lone_earth
                return earth[0] if earth else None

            earth_twin = [earth_twin_of(i) for i in range(len(self.sim.items))]
            loader = SourceAnchoredLoader(partial(HumanML3D.load_motion, self.sim), self.sim.items,
                                          [self._source_id(it) for it in self.sim.items],
                                          earth_twin, source_corpus(root, anchor_corpus),
                                          overlap=twin_frames == "overlap")
            self.sim.load_motion = loader  # type: ignore[method-assign]
            self.anchored = loader.anchored

    def _trim_to_common_prefix(self) -> int:
        """Trim the items of each (source clip, start, captions) group to the group's shortest; returns how many changed."""
        groups: dict[tuple[Any, ...], list[int]] = {}
        for i, it in enumerate(self.sim.items):
            groups.setdefault((self._source_id(it), it.start, tuple(it.captions)), []).append(i)
        changed = 0
        for members in groups.values():
            stop = min(self.sim.items[i].stop for i in members)  # items are built with >= 40 frames: so is the trim
            for i in members:
                if self.sim.items[i].stop != stop:
                    self.sim.items[i] = dataclasses.replace(self.sim.items[i], stop=stop)
                    changed += 1
        return changed

    def _twin_groups(self) -> dict[int, tuple[list[int], list[int]]]:
        """Per simulated item: (Earth twins, other twins) — items of the same source clip with the same frames (any
        last frame under ``twin_frames="overlap"``) and captions."""
        groups: dict[tuple[Any, ...], list[int]] = {}
        for i, it in enumerate(self.sim.items):
            stop = None if self.twin_frames == "overlap" else it.stop
            key = (self._source_id(it), it.start, stop, tuple(c.text for c in it.captions))
            groups.setdefault(key, []).append(i)
        twins: dict[int, tuple[list[int], list[int]]] = {}
        for members in groups.values():
            for i in members:
                others = [j for j in members if j != i]
                earth = [j for j in others if self._is_earth(j)]
                twins[i] = (earth, [j for j in others if j not in earth])
        return twins

    def _source_id(self, item: Item) -> str:
        """The source clip ``item`` was replayed from (env.json's ``source``; its own id when not recorded)."""
        return self.env_table[item.clip_id].get("source", item.clip_id)

    def _is_earth(self, index: int) -> bool:
        env = self.env_table[self.sim.items[index].clip_id]["env"]
        return abs(env[0] - EARTH_GRAVITY) < 1e-6 and abs(env[1]) < 1e-9 and abs(env[2]) < 1e-9

    def twin_count(self) -> int:
        """How many simulated items have a twin (0 for a binary augmentation: one φ per source clip)."""
        return sum(1 for earth, other in self._twins.values() if earth or other)

    def twin(self, index: int, rng: np.random.Generator) -> int | None:
        """A simulated item of the same source clip, frames and captions as ``index`` under another φ, or None.

        The Earth twin when there is one (so paired differences are effects relative to Earth, as the
        environment-response benchmark measures them); for an Earth item, one of its other twins drawn with ``rng``.
        Source (kinematic) items have no twins.
        """
        if not 0 <= index < len(self.sim):
            return None
        earth, other = self._twins[index]
        if earth:
            return earth[0]
        return other[int(rng.integers(len(other)))] if other and self._is_earth(index) else None

    def __len__(self) -> int:
        return len(self.sim) + (len(self.source) if self.source is not None else 0)

    def get(self, index: int, rng: np.random.Generator | None = None) -> dict[str, Any]:
        """Item ``index`` (simulated first, then source), drawn with ``rng``."""
        if not 0 <= index < len(self):
            raise SimdiffError(f"index {index} out of range for {len(self)} items")
        if index < len(self.sim):
            item = self.sim.get(index, rng)
            row = self.env_table[self.sim.items[index].clip_id]
            item["env"] = np.asarray(row["env"], dtype=np.float32)
            item["env_index"] = int(row["env_index"])
            return item
        assert self.source is not None
        item = self.source.get(index - len(self.sim), rng)
        item["env"] = np.array([EARTH_GRAVITY, 0.0, 0.0], dtype=np.float32)
        item["env_index"] = SOURCE_INDEX
        return item

    def __getitem__(self, index: int) -> dict[str, Any]:
        return self.get(index)


class ConcatItems:
    """Several datasets read as one (indices run through them in order); the first one's normaliser.

    Used to train on more than one simulator-augmented corpus (e.g. the random-φ set and the
    Earth-gravity binary set). All parts must share the normaliser (same source corpus Mean/Std).
    """

    def __init__(self, parts: list[Any]) -> None:
        if not parts:
            raise SimdiffError("no datasets to concatenate")
        self.parts = parts
        self.normalizer = getattr(parts[0], "normalizer", None)
        ref = self.normalizer
        for part in parts[1:]:
            other = getattr(part, "normalizer", None)
            if ref is not None and other is not None and not (np.allclose(np.asarray(ref.mean), np.asarray(other.mean))
                                                               and np.allclose(np.asarray(ref.std), np.asarray(other.std))):
                raise SimdiffError("the training corpora have different Mean/Std: augment them from one source corpus")
        self.offsets = np.cumsum([0] + [len(p) for p in parts])

    def __len__(self) -> int:
        return int(self.offsets[-1])

    def get(self, index: int, rng: np.random.Generator | None = None) -> dict[str, Any]:
        """Item ``index`` of the concatenation, drawn with ``rng``."""
        k, local = self._locate(index)
        part = self.parts[k]
        get = getattr(part, "get", None)
        return get(local, rng) if callable(get) else part[local]

    def twin_count(self) -> int:
        """Items with a twin, over all parts."""
        return sum(int(getattr(p, "twin_count", lambda: 0)()) for p in self.parts)

    def twin(self, index: int, rng: np.random.Generator) -> int | None:
        """The twin of item ``index`` within its own part (see :meth:`AugmentedHumanML3D.twin`), or None."""
        k, local = self._locate(index)
        twin = getattr(self.parts[k], "twin", None)
        found = twin(local, rng) if callable(twin) else None
        return None if found is None else found + int(self.offsets[k])

    def _locate(self, index: int) -> tuple[int, int]:
        """(part, index within it) of item ``index``."""
        if not 0 <= index < len(self):
            raise SimdiffError(f"index {index} out of range for {len(self)} items")
        k = int(np.searchsorted(self.offsets, index, side="right") - 1)
        return k, index - int(self.offsets[k])

    def __getitem__(self, index: int) -> dict[str, Any]:
        return self.get(index)


def open_training_dataset(root: str | Path | list[str | Path], split: str = "train", seed: int = 0,
                          source: str | Path | None = None, targets: str = "simulated",
                          anchor_corpus: str | Path | None = None,
                          twin_frames: str = "equal") -> HumanML3D | AugmentedHumanML3D | ConcatItems:
    """The dataset ``simdiff train`` should read from ``root``: augmented (with φ) when it has env.json.

    ``root`` may be a list of folders (concatenated; ``source`` is mixed in once). ``targets`` and
    ``anchor_corpus`` and ``twin_frames``: as :class:`AugmentedHumanML3D` (each augmented folder's own source corpus
    by default).
    """
    if isinstance(root, (list, tuple)):
        if len(root) == 1:
            return open_training_dataset(root[0], split, seed, source, targets, anchor_corpus, twin_frames)
        parts = [open_training_dataset(r, split, seed + 7 * i, source if i == 0 else None, targets, anchor_corpus,
                                       twin_frames)
                 for i, r in enumerate(root)]
        return ConcatItems(parts)
    if (Path(root) / ENV_FILE).is_file():
        return AugmentedHumanML3D(root, split, source=source, seed=seed, targets=targets, anchor_corpus=anchor_corpus,
                                  twin_frames=twin_frames)
    if twin_frames != "equal":
        raise SimdiffError(f"{root}: twin frames {twin_frames!r} need a simulator-augmented corpus (env.json)")
    if targets != "simulated":
        raise SimdiffError(f"{root}: {targets} targets need a simulator-augmented corpus (env.json)")
    return HumanML3D(root, split=split, seed=seed)
