"""Loader for a standard HumanML3D directory, following MDM's text-to-motion conventions.

Directory layout (``root``)::

    new_joint_vecs/<id>.npy   (T, 263) float32 features, 20 fps
    new_joints/<id>.npy       (T, 22, 3) joints in metres (not needed for training)
    texts/<id>.txt            lines ``caption#tokens#start#end`` (seconds; 0.0#0.0 = whole clip)
    Mean.npy, Std.npy         (263,) normalisation
    train.txt, val.txt, test.txt   one id per line

MDM rules reproduced here: a clip with < 40 or >= 200 frames is dropped (with all its
captions); a caption with a non-zero ``#start#end`` becomes its own item cut at
``int(tag * 20)`` (dropped if the cut has < 40 or >= 200 frames); the whole clip is an
item only if at least one caption covers it whole. Each item draws one of its captions at
random, is cropped to a multiple of ``unit_length`` frames (2/3: ``len//4*4``, 1/3:
``(len//4 - 1)*4``) at a random offset, normalised, and zero-padded to 196 frames.
"""

from __future__ import annotations

import dataclasses
import math
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import torch
from torch.utils.data import Dataset, get_worker_info

from simdiff.errors import MotionFormatError, SimdiffError
from simdiff.motion.normalize import FEATURE_DIM, Normalizer
from simdiff.motion.skeleton import FPS, MAX_FRAMES, MIN_FRAMES

MAX_CLIP_FRAMES: int = 200
"""Clips (and cuts) with this many frames or more are dropped (MDM: ``len >= 200``)."""

SPLITS: tuple[str, ...] = ("train", "val", "test", "train_val", "all")


@dataclass(frozen=True)
class Caption:
    """One line of a HumanML3D text file; ``start``/``end`` in seconds (0, 0 = whole clip)."""

    text: str
    tokens: tuple[str, ...]
    start: float
    end: float

    @property
    def whole(self) -> bool:
        """True when the caption describes the whole clip."""
        return self.start == 0.0 and self.end == 0.0


def split_path(root: Path, split: str) -> Path:
    """``root/<split>.txt`` for a standard split or any other split file in ``root`` (e.g. an augmented
    corpus's ``first_try``); a one-line error names an unknown one and the split files that exist."""
    path = root / f"{split}.txt"
    plain = split and "/" not in split and "\\" not in split and not split.startswith(".")
    if split in SPLITS or (plain and path.is_file()):
        return path
    extra = sorted(p.stem for p in root.glob("*.txt") if p.stem not in SPLITS)
    raise SimdiffError(f"unknown split {split!r}; expected one of {', '.join(SPLITS + tuple(extra))} "
                       f"(a split is a <name>.txt id list in {root})")


@dataclass(frozen=True)
class Item:
    """One dataset entry: frames [start, stop) of clip ``clip_id`` and its captions."""

    name: str
    clip_id: str
    start: int
    stop: int
    captions: tuple[Caption, ...]

    @property
    def length(self) -> int:
        """Frames before cropping."""
        return self.stop - self.start


def read_split(path: str | Path) -> list[str]:
    """Ids listed one per line in a split file (blank lines ignored)."""
    path = Path(path)
    if not path.is_file():
        raise SimdiffError(f"split file not found: {path}")
    return [line.strip() for line in path.read_text().splitlines() if line.strip()]


def _tag(value: str, path: Path, line: int) -> float:
    try:
        tag = float(value)
    except ValueError:
        raise MotionFormatError(path, f"bad start/end time {value!r}", line) from None
    return 0.0 if math.isnan(tag) else tag


def read_captions(path: str | Path) -> list[Caption]:
    """Parse a HumanML3D ``texts/<id>.txt`` file (``caption#tokens#start#end`` per line)."""
    path = Path(path)
    captions: list[Caption] = []
    for number, raw in enumerate(path.read_text(encoding="utf-8").splitlines(), start=1):
        if not raw.strip():
            continue
        parts = raw.strip().rsplit("#", 3)
        if len(parts) != 4:
            raise MotionFormatError(path, "expected 'caption#tokens#start#end'", number)
        text, tokens, start, end = parts
        captions.append(
            Caption(text, tuple(tokens.split()), _tag(start, path, number), _tag(end, path, number))
        )
    return captions


def _clip_frames(path: Path) -> int:
    """Number of frames of a (T, 263) ``.npy`` file, reading only its header."""
    try:
        arr = np.load(path, mmap_mode="r", allow_pickle=False)
    except (OSError, ValueError) as exc:
        raise SimdiffError(f"cannot read {path}: {exc}") from None
    if arr.ndim != 2 or arr.shape[1] != FEATURE_DIM:
        raise SimdiffError(f"{path} must hold (T, {FEATURE_DIM}) features, got {arr.shape}")
    return int(arr.shape[0])


def build_items(root: str | Path, ids: list[str], min_frames: int = MIN_FRAMES) -> list[Item]:
    """Dataset items for ``ids`` under ``root`` by MDM's rules (see module docstring).

    Ids whose motion or text file is missing are skipped, as MDM does. ``min_frames``: shortest
    clip or segment kept (MDM: 40 frames = 2 s at 20 fps; a 10 fps corpus keeps 2 s with 20).
    """
    root = Path(root)
    items: list[Item] = []
    for clip_id in ids:
        motion_path = root / "new_joint_vecs" / f"{clip_id}.npy"
        text_path = root / "texts" / f"{clip_id}.txt"
        if not motion_path.is_file() or not text_path.is_file():
            continue
        frames = _clip_frames(motion_path)
        if frames < min_frames or frames >= MAX_CLIP_FRAMES:
            continue
        whole: list[Caption] = []
        seen: dict[str, int] = {}
        for caption in read_captions(text_path):
            if caption.whole:
                whole.append(caption)
                continue
            start, stop = int(caption.start * FPS), int(caption.end * FPS)
            stop = min(stop, frames)  # Python slicing clips the end the same way
            if stop - start < min_frames or stop - start >= MAX_CLIP_FRAMES:
                continue
            name = f"{clip_id}_{start}_{stop}"
            seen[name] = seen.get(name, 0) + 1
            if seen[name] > 1:
                name = f"{name}_{seen[name] - 1}"
            items.append(Item(name, clip_id, start, stop, (caption,)))
        if whole:
            items.append(Item(clip_id, clip_id, 0, frames, tuple(whole)))
    return items


def normalise_caption(text: str) -> str:
    """The form in which two captions count as the same: lower case, letters and digits only, single spaces."""
    return " ".join(re.sub(r"[^a-z0-9]+", " ", text.lower()).split())


def split_captions(root: str | Path, split: str) -> list[str]:
    """The distinct captions of every clip listed in ``root/<split>.txt``, in file order."""
    root = Path(root)
    seen: dict[str, None] = {}
    for clip_id in read_split(split_path(root, split)):
        path = root / "texts" / f"{clip_id}.txt"
        if path.is_file():
            seen.update((c.text, None) for c in read_captions(path) if c.text.strip())
    return list(seen)


def unseen_items(items: list[Item], seen: set[str]) -> list[Item]:
    """``items`` with only the captions whose normalised form is not in ``seen``; items left without one dropped."""
    out = []
    for item in items:
        keep = tuple(c for c in item.captions if normalise_caption(c.text) not in seen)
        if keep:
            out.append(dataclasses.replace(item, captions=keep))
    return out


def crop_length(length: int, unit_length: int, rng: np.random.Generator) -> int:
    """MDM's crop: 2/3 ``length // u * u``, 1/3 ``(length // u - 1) * u`` (for u < 10)."""
    if unit_length >= 10:
        return length // unit_length * unit_length
    double = rng.integers(3) == 2
    return (length // unit_length - (1 if double else 0)) * unit_length


class HumanML3D(Dataset):
    """HumanML3D text-motion pairs as MDM feeds them to training and evaluation.

    Each item is ``dict(motion (196, 263) float32 normalised and zero-padded, length int, offset int (the crop's
    first frame within the item), caption str, tokens list[str], id str)``.

    Args:
        root: the HumanML3D directory.
        split: a split name (reads ``root/<split>.txt``) or an explicit list of ids.
        normalizer: defaults to ``root/Mean.npy`` and ``root/Std.npy``.
        unit_length: crop to multiples of this (MDM uses 4 in training and evaluation);
            0 disables the crop (clips longer than 196 frames are then cut to 196).
        max_frames: padded length (196).
        seed: seeds the caption/crop generator; each DataLoader worker (and each epoch of
            non-persistent workers) derives its own stream from it and the worker's seed.
        min_frames: shortest clip kept (MDM: 40; lower for a lower-frame-rate corpus).
        unseen_in: a split name: keep only the captions no clip of that split has (normalised,
            :func:`normalise_caption`), and the items left with one (the held-out captions of a test split).
    """

    def __init__(
        self,
        root: str | Path,
        split: str | list[str] = "train",
        normalizer: Normalizer | None = None,
        unit_length: int = 4,
        max_frames: int = MAX_FRAMES,
        seed: int = 0,
        min_frames: int = MIN_FRAMES,
        unseen_in: str | None = None,
    ) -> None:
        self.root = Path(root)
        if not self.root.is_dir():
            raise SimdiffError(f"HumanML3D directory not found: {self.root}")
        if unit_length < 0:
            raise SimdiffError(f"unit_length must be >= 0, got {unit_length}")
        if max_frames < MIN_FRAMES:
            raise SimdiffError(f"max_frames must be >= {MIN_FRAMES}, got {max_frames}")
        if isinstance(split, str):
            ids = read_split(split_path(self.root, split))
        else:
            ids = list(split)
        self.normalizer = normalizer if normalizer is not None else Normalizer.from_dir(self.root)
        self.unit_length = unit_length
        self.max_frames = max_frames
        self.random_offset = True  # False: every crop starts at the item's first frame (twins stay aligned)
        self.seed = seed
        self.items = build_items(self.root, ids, min_frames)
        if unseen_in is not None:
            seen = {normalise_caption(t) for t in split_captions(self.root, unseen_in)}
            self.items = unseen_items(self.items, seen)
            if not self.items:
                raise SimdiffError(f"{self.root}: no item of split {split!r} has a caption that {unseen_in!r} lacks")
        self._rng: np.random.Generator | None = None
        self._rng_key: int | None = None

    def __len__(self) -> int:
        return len(self.items)

    def _generator(self) -> np.random.Generator:
        info = get_worker_info()
        key = -1 if info is None else int(info.seed)
        if self._rng is None or key != self._rng_key:
            entropy = [self.seed] if info is None else [self.seed, key]
            self._rng = np.random.default_rng(entropy)
            self._rng_key = key
        return self._rng

    def load_motion(self, item: Item) -> np.ndarray:
        """Raw (un-normalised) features of ``item``, (length, 263) float32."""
        path = self.root / "new_joint_vecs" / f"{item.clip_id}.npy"
        return np.load(path, allow_pickle=False)[item.start : item.stop].astype(np.float32)

    def get(self, index: int, rng: np.random.Generator | None = None) -> dict[str, Any]:
        """Item ``index`` drawn with ``rng`` (defaults to the dataset's own generator)."""
        if not -len(self) <= index < len(self):
            raise SimdiffError(f"index {index} out of range for {len(self)} items")
        rng = self._generator() if rng is None else rng
        item = self.items[index]
        caption = item.captions[int(rng.integers(len(item.captions)))]
        motion = self.load_motion(item)
        length = len(motion)
        if self.unit_length:
            length = crop_length(length, self.unit_length, rng)
        length = min(length, self.max_frames)
        offset = int(rng.integers(len(motion) - length + 1)) if self.random_offset else 0
        out = np.zeros((self.max_frames, FEATURE_DIM), dtype=np.float32)
        out[:length] = self.normalizer.normalize(motion[offset : offset + length])
        return {
            "motion": out,
            "length": length,
            "caption": caption.text,
            "tokens": list(caption.tokens),
            "id": item.name,
            "offset": offset,
        }

    def __getitem__(self, index: int) -> dict[str, Any]:
        return self.get(index)


def collate(batch: list[dict[str, Any]]) -> dict[str, Any]:
    """Stack HumanML3D items.

    Returns:
        dict(motion (B, 196, 263) float32 tensor, lengths (B,) int64, mask (B, 196) bool
        (True on valid frames), captions list[str], tokens list[list[str]], ids list[str]).
    """
    if not batch:
        raise SimdiffError("cannot collate an empty batch")
    motion = torch.from_numpy(np.stack([b["motion"] for b in batch]))
    lengths = torch.tensor([b["length"] for b in batch], dtype=torch.int64)
    mask = torch.arange(motion.shape[1])[None, :] < lengths[:, None]
    return {
        "motion": motion,
        "lengths": lengths,
        "mask": mask,
        "captions": [b["caption"] for b in batch],
        "tokens": [b["tokens"] for b in batch],
        "ids": [b["id"] for b in batch],
    }


def corpus_captions(corpus: str | Path) -> list[str]:
    """Every caption of a HumanML3D-layout corpus (``texts/*.txt``, all splits), in file order, without repeats."""
    folder = Path(corpus) / "texts"
    if not folder.is_dir():
        raise SimdiffError(f"no texts/ folder in corpus {corpus}")
    seen: dict[str, None] = {}
    for path in sorted(folder.glob("*.txt")):
        for caption in read_captions(path):
            seen.setdefault(caption.text, None)
    return list(seen)
