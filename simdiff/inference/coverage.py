"""How near a prompt is to the captions a model trained on, and a one-line warning when it is far from all of them.

A model folder may hold ``captions.safetensors``: the distinct captions of its training split and their unit-length
text embeddings, (N, dim) float16, in the layout of :func:`simdiff.text.cache.write_caption_file`.
:func:`write_coverage_table` writes it (the training pipeline's export, and ``simdiff train coverage`` for an
existing folder). A prompt whose best cosine to every caption is below :data:`FAR_BELOW` is *far*: the model has
probably not seen that motion and will make something else; the warning names the nearest captions, i.e. the
nearest things it can do. A folder without the file is not checked.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Any

import torch
from torch import Tensor

from simdiff.errors import SimdiffError
from simdiff.text.base import TextEncoder

COVERAGE_NAME = "captions.safetensors"
"""File in a model folder with its training captions' embeddings."""

FAR_BELOW: float = 0.675  # MiniLM, shipped model: val 19/20 corpus motions silent, 19/20 absent ones warned; held-out 19/20, 18/20
"""A prompt whose best cosine to the training captions is below this is far from all of them: the middle of the val
lists' gap 0.671–0.681, which leaves one miss on each side (docs/design-notes.md; measured with MiniLM)."""

NEAREST: int = 3
"""Captions named in a warning."""

SAME_BELOW: float = 0.85
"""Two captions at a cosine of this or more are rewordings of one motion: a warning names only the nearer."""


@dataclass(frozen=True)
class PromptCoverage:
    """One prompt against a model's training captions.

    Attributes:
        text: the prompt.
        best: cosine (-1..1) to the nearest training caption.
        nearest: up to :data:`NEAREST` nearest captions, nearest first, no two rewordings of each other.
        far: ``best`` is below :data:`FAR_BELOW`.
    """

    text: str
    best: float
    nearest: tuple[str, ...]
    far: bool

    def warning(self) -> str | None:
        """The one-line warning for a far prompt (without a ``simdiff:`` prefix), None for a near one."""
        if not self.far:
            return None
        names = ", ".join(f'"{c}"' for c in self.nearest)
        return (f'"{self.text}" is far from every training caption (best match {self.best:.2f} < {FAR_BELOW:g}): '
                f"the motion may not follow it; nearest: {names}")

    def to_dict(self) -> dict[str, object]:
        """The ``generation.json`` record: text, best (3 decimals), far, nearest."""
        return {"text": self.text, "best": round(self.best, 3), "far": self.far, "nearest": list(self.nearest)}


def _unit(table: Tensor) -> Tensor:
    """(N, dim) → float32 rows of length 1 (zero rows stay zero)."""
    return torch.nn.functional.normalize(table.float(), dim=-1)


class CaptionIndex:
    """A model's training captions and their (N, dim) unit embeddings, to score prompts against."""

    def __init__(self, captions: Sequence[str], table: Tensor, encoder: str, path: str | os.PathLike[str] = "") -> None:
        if table.ndim != 2 or table.shape[0] != len(captions) or not captions:
            raise SimdiffError(f"{path or 'caption index'}: {tuple(table.shape)} embeddings for {len(captions)} captions")
        self.captions = list(captions)
        self.table = _unit(table)
        self.encoder = encoder
        self.path = Path(path)

    @classmethod
    def read(cls, path: str | os.PathLike[str]) -> CaptionIndex:
        """The index stored at ``path``; one :class:`SimdiffError` line naming the file when it is not one."""
        import json

        from safetensors import SafetensorError

        from simdiff.text.cache import read_caption_file

        try:
            captions, table, encoder = read_caption_file(path)
        except (SafetensorError, KeyError, json.JSONDecodeError, OSError, UnicodeDecodeError) as exc:
            raise SimdiffError(f"{path}: not a caption table ({type(exc).__name__}); rebuild it with "
                               "`simdiff train coverage CORPUS --model DIR`") from None
        return cls(captions, table, encoder, path)

    def check(self, texts: Sequence[str], embeddings: Tensor, encoder: str) -> list[PromptCoverage]:
        """Score (B,) prompts given their (B, dim) embeddings by the text encoder named ``encoder``."""
        if encoder != self.encoder:
            raise SimdiffError(f"{self.path}: holds {self.encoder!r} embeddings, the model uses {encoder!r}; rebuild "
                               "it with `simdiff train coverage CORPUS --model DIR`")
        if embeddings.ndim != 2 or embeddings.shape != (len(texts), self.table.shape[1]):
            raise SimdiffError(f"{self.path}: prompt embeddings of shape {tuple(embeddings.shape)}, expected "
                               f"({len(texts)}, {self.table.shape[1]})")
        scores = _unit(embeddings.detach().cpu()) @ self.table.T  # (B, N) cosines
        ranked = scores.topk(min(len(self.captions), 128), dim=1)
        out = []
        for text, values, rows in zip(texts, ranked.values.tolist(), ranked.indices.tolist()):
            kept: list[int] = []
            for row in rows:  # skip rewordings of a caption already named
                if all(float(self.table[row] @ self.table[k]) < SAME_BELOW for k in kept):
                    kept.append(row)
                if len(kept) == NEAREST:
                    break
            out.append(PromptCoverage(text, float(values[0]), tuple(self.captions[k] for k in kept),
                                      values[0] < FAR_BELOW))
        return out


@lru_cache(maxsize=4)
def _read_cached(path: str, mtime_ns: int, size: int) -> CaptionIndex:
    return CaptionIndex.read(path)


def load_caption_index(model_dir: str | os.PathLike[str]) -> CaptionIndex | None:
    """The model folder's :data:`COVERAGE_NAME` (cached while the file is unchanged), None when it has none."""
    path = Path(model_dir) / COVERAGE_NAME
    try:
        stat = path.stat()
    except OSError:
        return None
    return _read_cached(str(path), stat.st_mtime_ns, stat.st_size)


def check_prompts(model_dir: str | os.PathLike[str], texts: Sequence[str],
                  encode: Callable[[list[str]], Tensor], encoder: str) -> list[PromptCoverage] | None:
    """Each distinct prompt of ``texts`` scored against the model's training captions; None without a table.

    ``encode``: (B,) texts → (B, dim) embeddings with the model's text encoder, named ``encoder``.
    """
    index = load_caption_index(model_dir)
    if index is None:
        return None
    distinct = list(dict.fromkeys(texts))
    return index.check(distinct, encode(distinct), encoder) if distinct else []


def prompt_warnings(model_dir: str | os.PathLike[str], texts: Sequence[str], generator: Any) -> list[str]:
    """The one-line warnings of the distinct ``texts`` far from the model's training captions (none without a
    table), encoded by ``generator``'s text encoder (a stand-in's own name, else the model config's)."""
    try:
        if load_caption_index(model_dir) is None:  # no table: the generator's encoder is not even looked up
            return []
        name = getattr(generator.text_encoder, "name", None) or generator.config.text_encoder
        checked = check_prompts(model_dir, texts, generator.encode_text, name) or []
    except SimdiffError as exc:  # a broken or foreign table must not cost the motion it was asked about
        return [f"the prompt check was skipped: {exc}"]
    return [line for c in checked if (line := c.warning())]


def training_captions(corpus: str | os.PathLike[str], split: str = "train") -> list[str]:
    """The distinct captions of a HumanML3D-layout corpus's ``split`` (``<split>.txt`` ids, ``texts/<id>.txt``)."""
    from simdiff.data.humanml3d import split_captions

    root = Path(corpus)
    seen = split_captions(root, split)  # as training encoded them
    if not seen:
        raise SimdiffError(f"{root}: no captions in split {split!r} (texts/<id>.txt)")
    return seen


def write_coverage_table(model_dir: str | os.PathLike[str], captions: Iterable[str], encoder: TextEncoder,
                         chunk: int = 256) -> dict[str, object]:
    """Encode the distinct ``captions`` with ``encoder`` (the model's text encoder) and write
    ``model_dir/captions.safetensors`` (unit rows, float16; atomic). Returns captions, dim and bytes."""
    from simdiff.text.cache import write_caption_file

    texts = list(dict.fromkeys(t for t in captions if t.strip()))
    if not texts:
        raise SimdiffError("no captions to write a caption table from")
    table = torch.cat([_unit(encoder.encode(texts[i:i + chunk]).detach().cpu()) for i in range(0, len(texts), chunk)])
    path = Path(model_dir) / COVERAGE_NAME
    write_caption_file(path, texts, table.half().contiguous(), encoder.name)
    return {"captions": len(texts), "dim": int(table.shape[1]), "bytes": path.stat().st_size}
