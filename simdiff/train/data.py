"""The dataset protocol the trainer needs, deterministic batching, and a synthetic dataset for tests.

Any ``Sequence``-like object with ``__len__`` and ``__getitem__`` (optionally
``get(index, rng)``) returning ``dict(motion (196, 263) float32 normalised zero-padded,
length int, caption str, ...)`` works; ``simdiff.data.humanml3d.HumanML3D`` is one. Simulator-
augmented items add ``env`` (3,) float32 φ = (g_z, w_x, w_y) and/or ``env_index`` int.
"""

from __future__ import annotations

from typing import Any, Protocol, Sequence

import numpy as np
import torch
from torch import Tensor

from simdiff.data.batch import collate
from simdiff.errors import SimdiffError
from simdiff.train.geometric import crop_batch


class MotionDataset(Protocol):
    """What the trainer reads: items as described in the module docstring."""

    def __len__(self) -> int: ...

    def __getitem__(self, index: int) -> dict[str, Any]: ...


def fetch(dataset: MotionDataset, index: int, rng: np.random.Generator) -> dict[str, Any]:
    """Item ``index``, drawn with ``rng`` when the dataset supports it (so runs are reproducible)."""
    get = getattr(dataset, "get", None)
    return get(index, rng) if callable(get) else dataset[index]


class StepBatcher:
    """Which dataset indices step k uses: a fresh seeded permutation per epoch, sliced per process.

    Depends only on ``(seed, step, rank)``, so an interrupted run resumes on the same batches.
    """

    def __init__(self, size: int, batch_size: int, seed: int, world_size: int = 1, rank: int = 0) -> None:
        if size <= 0:
            raise SimdiffError("the training dataset is empty")
        if batch_size % world_size:
            raise SimdiffError(f"batch size {batch_size} is not divisible by {world_size} processes")
        self.size = size
        self.global_batch = batch_size
        self.local_batch = batch_size // world_size
        self.seed = seed
        self.rank = rank
        self._perms: dict[int, Tensor] = {}

    def _perm(self, epoch: int) -> Tensor:
        if epoch not in self._perms:
            if len(self._perms) > 4:
                self._perms.pop(min(self._perms))
            g = torch.Generator().manual_seed(self.seed * 1_000_003 + epoch)
            self._perms[epoch] = torch.randperm(self.size, generator=g)
        return self._perms[epoch]

    def indices(self, step: int) -> list[int]:
        """This process's dataset indices for step ``step``."""
        start = step * self.global_batch + self.rank * self.local_batch
        return [int(self._perm(p // self.size)[p % self.size]) for p in range(start, start + self.local_batch)]


class TensorMotionDataset:
    """Items from in-memory normalised clips, for tests, demos and overfitting checks.

    Args:
        motions: list of (L_i, 263) float32 normalised features (L_i ≤ max_frames).
        captions: one caption per clip.
        envs: optional (3,) φ per clip; env_indices: optional int per clip.
        max_frames: padded length (196).
    """

    def __init__(self, motions: Sequence[np.ndarray | Tensor], captions: Sequence[str],
                 envs: Sequence[Sequence[float]] | None = None, env_indices: Sequence[int] | None = None,
                 max_frames: int = 196) -> None:
        if len(motions) != len(captions):
            raise SimdiffError("need one caption per motion")
        self.motions = [np.asarray(m, dtype=np.float32) for m in motions]
        self.captions = list(captions)
        self.envs = None if envs is None else [np.asarray(e, dtype=np.float32) for e in envs]
        self.env_indices = None if env_indices is None else [int(i) for i in env_indices]
        self.max_frames = max_frames

    def __len__(self) -> int:
        return len(self.motions)

    def __getitem__(self, index: int) -> dict[str, Any]:
        m = self.motions[index][: self.max_frames]
        out = np.zeros((self.max_frames, m.shape[1]), dtype=np.float32)
        out[: len(m)] = m
        item: dict[str, Any] = {"motion": out, "length": len(m), "caption": self.captions[index],
                                "tokens": self.captions[index].split(), "id": f"{index:06d}"}
        if self.envs is not None:
            item["env"] = self.envs[index]
        if self.env_indices is not None:
            item["env_index"] = self.env_indices[index]
        return item


def synthetic_dataset(num_clips: int = 8, frames: int = 60, max_frames: int = 196, seed: int = 0,
                      with_env: bool = False) -> TensorMotionDataset:
    """Smooth random normalised clips (low-frequency sinusoids) with distinct captions.

    No motion semantics: for smoke tests of the training machinery only.
    """
    rng = np.random.default_rng(seed)
    t = np.arange(frames, dtype=np.float32)[:, None] / 20.0
    motions, captions, envs = [], [], []
    for i in range(num_clips):
        freq = rng.uniform(0.2, 1.5, size=(1, 263)).astype(np.float32)
        phase = rng.uniform(0, 2 * np.pi, size=(1, 263)).astype(np.float32)
        motions.append(np.sin(2 * np.pi * freq * t + phase).astype(np.float32))
        captions.append(f"synthetic motion number {i}")
        envs.append([float(rng.uniform(-15, -3)), float(rng.uniform(-10, 10)), float(rng.uniform(-10, 10))])
    return TensorMotionDataset(motions, captions, envs if with_env else None, max_frames=max_frames)


def _aligned(a: dict[str, Any], b: dict[str, Any]) -> bool:
    """Whether two twins' frames line up: equal lengths (one crop for both), or both cropped from their first frame
    (twins of unequal length, ``twin_frames="overlap"``: compared over the frames they share)."""
    if int(a["length"]) == int(b["length"]):
        return True
    return a.get("offset", -1) == 0 and b.get("offset", -1) == 0


class StepBatches(torch.utils.data.Dataset):
    """The collated, cropped batches of steps ``start .. end - 1`` of a run, item ``i`` being step ``start + i``.

    A batch depends only on ``(seed, step, rank)``, so DataLoader worker processes can build them ahead of the
    training loop (``Trainer(loader_workers=N)``) and the run stays bit-identical to building them in-process.
    """

    def __init__(self, dataset: MotionDataset, batcher: StepBatcher, seed: int, rank: int, crop: Any,
                 start: int = 0, end: int = 0, pairs: bool = False) -> None:
        self.dataset, self.batcher, self.seed, self.rank, self.crop = dataset, batcher, seed, rank, crop
        self.start, self.end = start, end
        if pairs and (not callable(getattr(dataset, "twin", None)) or getattr(dataset, "twin_count", lambda: 1)() == 0):
            raise SimdiffError("paired batches need a simulator-augmented dataset with twins (items of one source clip "
                               "under several φ: `simdiff data augment --mode paired`)")
        if pairs and batcher.local_batch % 2:
            raise SimdiffError(f"paired batches need an even batch per process, got {batcher.local_batch}")
        self.pairs = pairs

    def __len__(self) -> int:
        return max(0, self.end - self.start)

    def batch(self, step: int) -> dict[str, Any]:
        """The batch of ``step`` for this process."""
        rng = np.random.default_rng([self.seed, step, self.rank])
        if self.pairs:
            return self._paired(step, rng)
        batch = collate([fetch(self.dataset, i, rng) for i in self.batcher.indices(step)])
        return crop_batch(batch, self.crop, rng)

    def _paired(self, step: int, rng: np.random.Generator) -> dict[str, Any]:
        """h = B/2 anchors (the first half of the step's indices) then their twins, drawn alike; ``paired`` (h,) bool.

        An anchor without a twin is repeated (``paired`` False: it counts in the plain loss only).
        """
        anchors = self.batcher.indices(step)[: self.batcher.local_batch // 2]
        first, second, paired = [], [], []
        for j, index in enumerate(anchors):
            twin = self.dataset.twin(index, np.random.default_rng([self.seed, step, self.rank, j, 1]))  # type: ignore[attr-defined]
            first.append(fetch(self.dataset, index, np.random.default_rng([self.seed, step, self.rank, j, 0])))
            second.append(fetch(self.dataset, index if twin is None else twin,
                                np.random.default_rng([self.seed, step, self.rank, j, 0])))
            paired.append(twin is not None and _aligned(first[-1], second[-1]))
        batch = crop_batch(collate(first + second), self.crop, rng, pairs=len(anchors))
        batch["paired"] = torch.tensor(paired, dtype=torch.bool)
        return batch

    def __getitem__(self, index: int) -> dict[str, Any]:
        return self.batch(self.start + index)
