"""Precomputed caption embeddings as a frozen text encoder (for machines without the encoder's weights).

A GPU machine lent for training has no internet and no room to carry MiniLM's 88 MB of weights
within its 64 MiB; a corpus's captions are few (the all-source corpus: 2,753 distinct captions, 2 MiB as
float16), so they are encoded here once (``simdiff train text-table``) and the pipeline reads
them there (``simdiff train pipeline --text-table FILE``). A caption that is not in the table is
an error naming it, never a silent zero vector. The file has the layout of
:func:`simdiff.text.cache.write_caption_file`, shared with the training caption cache.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Iterable, Sequence

import torch
from torch import Tensor

from simdiff.errors import SimdiffError
from simdiff.text.base import TextEncoder
from simdiff.text.cache import read_caption_file, write_caption_file


class CaptionTable:
    """A :class:`~simdiff.text.base.TextEncoder` that looks captions up in a table file.

    Attributes:
        name: the encoder that filled the table (``"minilm"``): models trained with the table load
            with that encoder at inference.
        dim: embedding size.
    """

    def __init__(self, path: str | os.PathLike[str], device: torch.device | str = "cpu") -> None:
        from safetensors import SafetensorError

        self.path = Path(path)
        if not self.path.is_file():
            raise SimdiffError(f"text table not found: {self.path}")
        try:
            captions, table, self.name = read_caption_file(self.path)
            table = table.float()
        except (SafetensorError, KeyError, json.JSONDecodeError, OSError) as exc:
            raise SimdiffError(f"{self.path}: not a text table ({type(exc).__name__}); "
                               "write one with `simdiff train text-table`") from None
        if table.ndim != 2 or table.shape[0] != len(captions):
            raise SimdiffError(f"{self.path}: {table.shape[0]} embeddings for {len(captions)} captions")
        self.dim = int(table.shape[1])
        self.device = torch.device(device)
        self._table = table
        self._row = {text: i for i, text in enumerate(captions)}

    def __len__(self) -> int:
        return len(self._row)

    def encode(self, texts: Sequence[str]) -> Tensor:
        """(B,) captions → (B, dim) float32 on ``device``; a caption missing from the table is an error."""
        rows = []
        for text in texts:
            row = self._row.get(text)
            if row is None:
                raise SimdiffError(f"caption {text!r} is not in the text table {self.path}; rebuild it with "
                                   "`simdiff train text-table` over every corpus and prompt the run uses")
            rows.append(row)
        return self._table[torch.tensor(rows, dtype=torch.long)].to(self.device) if rows else \
            torch.zeros(0, self.dim, device=self.device)


def open_caption_table(path: str | os.PathLike[str], encoder: str, device: torch.device | str = "cpu") -> CaptionTable:
    """The table at ``path``, refused in one line unless its embeddings come from ``encoder`` (e.g. ``"minilm"``)."""
    table = CaptionTable(path, device)
    if table.name != encoder:
        raise SimdiffError(f"text table {path} holds {table.name!r} embeddings, the run uses {encoder!r}")
    return table


def write_caption_table(captions: Iterable[str], encoder: TextEncoder, out: str | os.PathLike[str],
                        dtype: str = "float16", chunk: int = 256) -> dict[str, object]:
    """Encode ``captions`` (plus the empty caption) with ``encoder`` and write the table atomically.

    ``dtype``: ``float16`` (half the size; within about 1e-3 of the float32 vectors) or ``float32``.
    Returns a summary (captions, dim, dtype, bytes).
    """
    if dtype not in ("float16", "float32"):
        raise SimdiffError(f"text table dtype must be float16 or float32, got {dtype!r}")
    texts = list(dict.fromkeys(["", *captions]))
    parts = [encoder.encode(texts[i:i + chunk]).float().cpu() for i in range(0, len(texts), chunk)]
    table = torch.cat(parts).to(getattr(torch, dtype)).contiguous()
    write_caption_file(out, texts, table, encoder.name)
    return {"captions": len(texts), "dim": int(table.shape[1]), "dtype": dtype, "bytes": Path(out).stat().st_size}
