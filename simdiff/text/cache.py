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
        import json

        from simdiff.model.checkpoint import atomic_save_tensors

        texts = list(self._cache)
        table = torch.stack([self._cache[t] for t in texts]) if texts else torch.zeros(0, self.dim)
        atomic_save_tensors({"embeddings": table}, path, metadata={"captions": json.dumps(texts), "encoder": self.name})

    def load(self, path: str | os.PathLike[str]) -> None:
        """Add the entries stored at ``path`` (written by :meth:`save` with the same encoder)."""
        import json

        from safetensors import safe_open

        if not Path(path).is_file():
            return
        with safe_open(str(path), "pt") as f:
            meta = f.metadata() or {}
            if meta.get("encoder") != self.name:
                return
            table = f.get_tensor("embeddings")
        for text, vec in zip(json.loads(meta.get("captions", "[]")), table):
            self._cache[text] = vec
