"""Cache of caption embeddings so training encodes each caption once."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Sequence

import torch
from torch import Tensor

from simdiff.text.base import TextEncoder


class CachedTextEncoder:
    """Wrap a :class:`TextEncoder`; ``encode`` computes only unseen captions (in chunks).

    Embeddings are kept on CPU as float32 and returned on ``device``. ``save``/``load``
    persist the cache as a safetensors file (captions in its metadata order).
    """

    def __init__(self, encoder: TextEncoder, device: torch.device | str = "cpu", chunk: int = 256) -> None:
        self.encoder = encoder
        self.name = encoder.name
        self.dim = encoder.dim
        self.device = torch.device(device)
        self.chunk = chunk
        self._cache: dict[str, Tensor] = {}

    def __len__(self) -> int:
        return len(self._cache)

    def encode(self, texts: Sequence[str]) -> Tensor:
        """(B,) captions → (B, dim) float32 on ``self.device``."""
        missing = list(dict.fromkeys(t for t in texts if t not in self._cache))
        for start in range(0, len(missing), self.chunk):
            part = missing[start : start + self.chunk]
            for text, vec in zip(part, self.encoder.encode(part).float().cpu()):
                self._cache[text] = vec
        if not texts:
            return torch.zeros(0, self.dim, device=self.device)
        return torch.stack([self._cache[t] for t in texts]).to(self.device)

    def save(self, path: str | os.PathLike[str]) -> None:
        """Write the cache to ``path`` (safetensors; atomic)."""
        texts = list(self._cache)
        table = torch.stack([self._cache[t] for t in texts]) if texts else torch.zeros(0, self.dim)
        write_caption_file(path, texts, table, self.name)

    def load(self, path: str | os.PathLike[str]) -> None:
        """Add the entries stored at ``path`` (written by :meth:`save` with the same encoder)."""
        if not Path(path).is_file():
            return
        try:
            captions, table, encoder = read_caption_file(path)
        except KeyError:  # no encoder or captions recorded: nothing usable
            return
        if encoder != self.name:
            return
        for text, vec in zip(captions, table):
            self._cache[text] = vec


def write_caption_file(path: str | os.PathLike[str], captions: list[str], table: Tensor, encoder: str) -> None:
    """Write (N,) captions and their (N, dim) embeddings atomically: safetensors ``embeddings``, the captions
    and the encoder's name in the metadata (the format of the cache and of :mod:`simdiff.text.table`)."""
    import json

    from simdiff.fsio import atomic_save_tensors

    atomic_save_tensors({"embeddings": table}, path, metadata={"captions": json.dumps(captions), "encoder": encoder})


def read_caption_file(path: str | os.PathLike[str]) -> tuple[list[str], Tensor, str]:
    """(captions, (N, dim) embeddings in their stored dtype, encoder name) of a :func:`write_caption_file` file.

    Raises the reader's own errors on a file that is not one (``SafetensorError``, ``KeyError``,
    ``json.JSONDecodeError``, ``OSError``); callers turn them into their own messages.
    """
    import json

    from safetensors import safe_open

    with safe_open(str(path), "pt") as f:
        meta = f.metadata() or {}
        table = f.get_tensor("embeddings")
    return json.loads(meta["captions"]), table, str(meta["encoder"])
