"""Source-anchored training targets for the adapters (``simdiff train adapters --targets source-anchored``).

A simulated item's plain target is the simulator's replay x_sim(φ) (frames × 263 HumanML3D features). The tracker's
Earth replays are far from the clips they replay (measured: R@3 0.18–0.28 below ground truth, FID
14–24), so adapters trained on plain targets also learn the tracker's look. A source-anchored target keeps only the
simulator's *change* under φ:

    x_source + (x_sim(φ) − x_sim(Earth))

with x_source the source clip's frames (the corpus the augmentation replayed) and x_sim(Earth) the item's Earth twin
(the same source clip, frames and captions replayed at Earth). An Earth item's target is the source clip itself. The
four foot-contact channels are clipped to [0, 1]. Where the source frames, the item and its Earth twin differ in
length (a re-timed rollout), or no Earth twin was kept, the item keeps its plain target — except with
``overlap=True`` (``--twin-frames overlap``), where :func:`anchor_overlap` anchors the frames all three share and
holds the last shared frame's pose correction after them.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from simdiff.errors import SimdiffError

if TYPE_CHECKING:
    from simdiff.data.humanml3d import Item

TARGETS: tuple[str, ...] = ("simulated", "source-anchored", "source-anchored-pairs")
"""Training targets ``simdiff train adapters --targets`` accepts."""
CONTACTS = slice(259, 263)
"""The four foot-contact channels of the 263 HumanML3D features (0 or 1)."""
POSE = slice(3, 193)
"""The pose channels of the 263 features: root height, root-relative joint positions, joint rotations (6D); the rest
are velocities (root 0:3, joints 193:259) and foot contacts."""
SOURCE_RECORD = "source_corpus.json"


def anchor(simulated: np.ndarray, earth: np.ndarray, source: np.ndarray) -> np.ndarray:
    """x_source + (x_sim(φ) − x_sim(Earth)), contacts clipped to [0, 1]; all (frames, 263) float32, equal lengths."""
    if not simulated.shape == earth.shape == source.shape:
        raise SimdiffError(f"anchor: shapes differ ({simulated.shape}, {earth.shape}, {source.shape})")
    out = (source + (simulated - earth)).astype(np.float32)
    out[:, CONTACTS] = np.clip(out[:, CONTACTS], 0.0, 1.0)
    return out


def anchor_overlap(simulated: np.ndarray, earth: np.ndarray, source: np.ndarray) -> np.ndarray:
    """:func:`anchor` over the n frames all three share; a replay longer than n keeps, after them, its own frames
    plus the pose correction (source − Earth replay) of frame n − 1 on the :data:`POSE` channels (velocities and
    contacts as simulated). A low-gravity replay that flies longer than its Earth twin thus keeps its whole flight
    and landing. All (frames, 263) float32, from the same first frame; returns ``simulated``'s length."""
    n = min(len(simulated), len(earth), len(source))
    if n == 0:
        raise SimdiffError("anchor_overlap: no common frames")
    out = simulated.astype(np.float32, copy=True)
    out[:n] += source[:n] - earth[:n]
    out[n:, POSE] += source[n - 1, POSE] - earth[n - 1, POSE]
    out[:, CONTACTS] = np.clip(out[:, CONTACTS], 0.0, 1.0)
    return out


def source_corpus(root: str | Path, override: str | Path | None = None) -> Path:
    """The source corpus of augmented corpus ``root``: ``override``, else the path in ``root/source_corpus.json``."""
    if override is None:
        record = Path(root) / SOURCE_RECORD
        try:
            override = json.loads(record.read_text(encoding="utf-8"))["path"]
        except (OSError, ValueError, KeyError, TypeError):
            raise SimdiffError(f"{record}: no source corpus path recorded (pass --anchor-corpus PATH)") from None
    path = Path(override)
    if not (path / "new_joint_vecs").is_dir():
        raise SimdiffError(f"source corpus {path}: no new_joint_vecs/ folder (source-anchored targets read the "
                           f"clips {root} was augmented from; pass --anchor-corpus PATH)")
    return path


class SourceAnchoredLoader:
    """A ``load_motion`` replacement: (item) → its source-anchored target, raw features (length, 263) float32.

    Args:
        load: the plain loader (the simulated corpus's ``load_motion``).
        items: the simulated items.
        sources: per item, the source clip id it was replayed from.
        earth_twin: per item, the index of its Earth twin, ``-1`` for an Earth item, None when none was kept.
        corpus: the source corpus folder (``new_joint_vecs/<id>.npy``).
        overlap: anchor a simulated item whose length differs from its Earth twin's or source's with
            :func:`anchor_overlap` (an Earth item: with itself as the Earth replay, so it is the source clip over
            their common frames and the twins' anchored difference is the simulated one); default: it keeps its
            replay.
    """

    def __init__(self, load: Callable[[Item], np.ndarray], items: list[Item], sources: list[str],
                 earth_twin: list[int | None], corpus: Path, overlap: bool = False) -> None:
        self.load, self.items, self.corpus, self.overlap = load, items, corpus, overlap
        self._plan = {it.name: (src, twin) for it, src, twin in zip(items, sources, earth_twin)}
        self.anchored = sum(self._usable(it) for it in items)

    def _source(self, name: str, start: int, stop: int, mmap: bool = False) -> np.ndarray:
        path = self.corpus / "new_joint_vecs" / f"{name}.npy"
        if not path.is_file():
            raise SimdiffError(f"source corpus {self.corpus}: no clip {name!r} (is it the corpus this was augmented from?)")
        return np.load(path, mmap_mode="r" if mmap else None, allow_pickle=False)[start:stop]

    def _usable(self, item: Item) -> bool:
        src, twin = self._plan[item.name]
        if twin is None:
            return False
        n = self._source(src, item.start, item.stop, mmap=True).shape[0]
        if self.overlap:
            return n > 0
        return n == item.length == (item.length if twin < 0 else self.items[twin].length)

    def __call__(self, item: Item) -> np.ndarray:
        plain = self.load(item)
        src_id, twin = self._plan[item.name]
        if twin is None:
            return plain
        src = self._source(src_id, item.start, item.stop).astype(np.float32)
        if twin < 0:
            if len(src) == len(plain):
                return src
            return anchor_overlap(plain, plain, src) if self.overlap and len(src) else plain
        earth = self.load(self.items[twin])
        if len(src) == len(plain) == len(earth):
            return anchor(plain, earth, src)
        return anchor_overlap(plain, earth, src) if self.overlap and len(src) else plain
