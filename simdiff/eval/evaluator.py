"""Our text–motion contrastive evaluator, in the spirit of Guo et al. (2022).

Motion side (as T2M): the 263-d features without the 4 foot contacts (259 channels), in the
evaluator's normalised space, go through a *movement encoder* (two stride-2 convolutions:
one token per 4-frame unit) and a bidirectional GRU with a learned initial state, packed
by ``length // 4``; the two final states → MLP → embedding (``embed_dim``).

Text side (our choice, differs from T2M): T2M's GloVe + POS BiGRU needs GloVe files and a
spaCy tagger; we use the project's MiniLM sentence embedding (384-d, frozen, cached) and a
small MLP (Linear → LayerNorm → LeakyReLU → Linear) onto the same embedding space. MiniLM
already encodes word order, and its token states are not exposed by the encoder interface.
Caveat: a generator conditioned on the same MiniLM embeddings may be favoured on
R-precision / MM-Dist; compare models under one evaluator, and use the official T2M
evaluator (:mod:`simdiff.eval.t2m_official`) for numbers comparable with the literature.

Evaluator space: ``x_eval = (x − Mean)/Std`` with the corpus Mean/Std stored in the weights,
and the root channels [0:4] multiplied by ``feat_bias`` (T2M divides their std by 5).

Training: Guo's contrastive loss on Euclidean distance — positives ``d²``, negatives (the
batch cyclically shifted by a random offset, pairs with an identical caption skipped)
``max(0, margin − d)²`` — Adam, gradient-norm clip 0.5; the best checkpoint on the
validation split by R-precision top-1 (or the last one without a val split) is exported as
``model.safetensors`` + ``config.json``.
"""

from __future__ import annotations

import dataclasses
import json
import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import torch
from torch import Tensor, nn

from simdiff.errors import SimdiffError
from simdiff.eval.encoders import BiGRUEncoder, MovementConvEncoder
from simdiff.motion.normalize import Normalizer

CONTACT_DIMS: int = 4
ROOT_DIMS: int = 4


@dataclass
class EvaluatorConfig:
    """Evaluator architecture and evaluator-space normalisation.

    Attributes:
        feat_dim: motion features per frame (263); the last 4 (contacts) are dropped.
        unit_length: frames per movement token (4: two stride-2 convolutions).
        movement_dim: movement encoder width (T2M: 512).
        motion_hidden: motion BiGRU width (T2M: 1024).
        text_dim: text embedding size in (MiniLM: 384).
        text_hidden: text MLP width.
        embed_dim: shared embedding size (T2M: 512).
        dropout: movement encoder dropout (T2M: 0.2).
        feat_bias: multiplier of the normalised root channels [0:4].
        text_encoder: name of the text encoder the text side expects.
    """

    feat_dim: int = 263
    unit_length: int = 4
    movement_dim: int = 256
    motion_hidden: int = 512
    text_dim: int = 384
    text_hidden: int = 512
    embed_dim: int = 256
    dropout: float = 0.2
    feat_bias: float = 5.0
    text_encoder: str = "minilm"


def _init(module: nn.Module) -> None:
    if isinstance(module, (nn.Linear, nn.Conv1d)):
        nn.init.xavier_normal_(module.weight)
        if module.bias is not None:
            nn.init.zeros_(module.bias)


class MovementEncoder(MovementConvEncoder):
    """(B, T, C) → (B, T // 4, D) movement tokens (two stride-2 convolutions, then a linear)."""

    def __init__(self, in_dim: int, dim: int, dropout: float) -> None:
        super().__init__(in_dim, dim, dim, dropout)
        self.apply(_init)


class SequenceEncoder(BiGRUEncoder):
    """(B, N, in) tokens with (B,) valid counts → (B, out): BiGRU with learned h0, final states → MLP."""

    def __init__(self, in_dim: int, hidden: int, out_dim: int) -> None:
        super().__init__(in_dim, hidden, out_dim)
        self.hidden = nn.Parameter(torch.randn(2, 1, hidden))
        self.input_emb.apply(_init)
        self.output_net.apply(_init)

    def forward(self, tokens: Tensor, counts: Tensor) -> Tensor:
        return self.encode(tokens, counts)


class TextProjector(nn.Module):
    """(B, text_dim) sentence embeddings → (B, embed_dim)."""

    def __init__(self, in_dim: int, hidden: int, out_dim: int) -> None:
        super().__init__()
        self.net = nn.Sequential(nn.Linear(in_dim, hidden), nn.LayerNorm(hidden), nn.LeakyReLU(0.2), nn.Linear(hidden, out_dim))
        self.apply(_init)

    def forward(self, x: Tensor) -> Tensor:
        return self.net(x)


class TextMotionEvaluator(nn.Module):
    """Motion and text encoders into one embedding space, plus the evaluator-space statistics.

    Buffers ``mean``/``std`` (263,) are the corpus statistics the evaluator normalises with.
    """

    def __init__(self, config: EvaluatorConfig, mean: Tensor | None = None, std: Tensor | None = None) -> None:
        super().__init__()
        self.config = config
        c = config
        in_dim = c.feat_dim - CONTACT_DIMS
        self.movement = MovementEncoder(in_dim, c.movement_dim, c.dropout)
        self.motion = SequenceEncoder(c.movement_dim, c.motion_hidden, c.embed_dim)
        self.text = TextProjector(c.text_dim, c.text_hidden, c.embed_dim)
        self.register_buffer("mean", torch.zeros(c.feat_dim) if mean is None else torch.as_tensor(mean).float())
        self.register_buffer("std", torch.ones(c.feat_dim) if std is None else torch.as_tensor(std).float())

    def to_eval_space(self, features: Tensor) -> Tensor:
        """(B, T, 263) raw features → normalised, root ×feat_bias, contacts dropped: (B, T, 259)."""
        x = (features - self.mean) / self.std
        scale = torch.ones(x.shape[-1], device=x.device, dtype=x.dtype)
        scale[:ROOT_DIMS] = self.config.feat_bias
        return (x * scale)[..., : -CONTACT_DIMS]

    def encode_motion(self, x_eval: Tensor, lengths: Tensor) -> Tensor:
        """(B, T, 259) evaluator-space features, (B,) frames → (B, embed_dim)."""
        tokens = self.movement(x_eval)
        return self.motion(tokens, torch.as_tensor(lengths) // self.config.unit_length)

    def embed_motion(self, features: Tensor, lengths: Tensor | Sequence[int]) -> Tensor:
        """(B, T, 263) raw (un-normalised) features with (B,) valid frames → (B, embed_dim).

        Frames beyond each length are zeroed in evaluator space (as the T2M loaders pad).
        """
        lengths = torch.as_tensor(lengths, dtype=torch.long)
        x = self.to_eval_space(features.float().to(self.mean.device))
        mask = torch.arange(x.shape[1], device=x.device)[None] < lengths.to(x.device)[:, None]
        return self.encode_motion(x * mask[..., None], lengths)

    def embed_text_vectors(self, vectors: Tensor) -> Tensor:
        """(B, text_dim) sentence embeddings → (B, embed_dim)."""
        return self.text(vectors.float().to(self.mean.device))


def save_evaluator(folder: str | os.PathLike[str], model: TextMotionEvaluator, extra: dict[str, Any] | None = None) -> None:
    """Write ``model.safetensors`` and ``config.json`` (``{"evaluator": config, **extra}``) atomically."""
    from simdiff.fsio import atomic_save_tensors
    from simdiff.model.checkpoint import atomic_write_json

    folder = Path(folder)
    atomic_save_tensors(model.state_dict(), folder / "model.safetensors", metadata={"library": "simdiff", "kind": "t2m-evaluator"})
    atomic_write_json({"evaluator": dataclasses.asdict(model.config), **(extra or {})}, folder / "config.json")


def load_evaluator(folder: str | os.PathLike[str], device: torch.device | str = "cpu") -> TextMotionEvaluator:
    """Load an evaluator folder written by :func:`save_evaluator` (eval mode, no gradients)."""
    from safetensors.torch import load_file

    from simdiff.model.config import config_from_dict

    folder = Path(folder)
    for name in ("model.safetensors", "config.json"):
        if not (folder / name).is_file():
            raise SimdiffError(f"{folder / name}: missing evaluator file")
    try:
        raw = json.loads((folder / "config.json").read_text(encoding="utf-8"))
    except json.JSONDecodeError as exc:
        raise SimdiffError(f"{folder / 'config.json'}: invalid JSON ({exc.msg})") from None
    if "evaluator" not in raw:
        raise SimdiffError(f"{folder / 'config.json'}: not an evaluator config (no 'evaluator' key)")
    config = config_from_dict(raw["evaluator"], EvaluatorConfig)
    model = TextMotionEvaluator(config)
    state = load_file(str(folder / "model.safetensors"))
    try:
        model.load_state_dict(state, strict=True)
    except RuntimeError as exc:
        raise SimdiffError(f"{folder / 'model.safetensors'}: weights do not match config.json ({str(exc).splitlines()[0]})") from None
    return model.to(device).eval().requires_grad_(False)


class OurEvaluator:
    """The evaluator interface used by the protocol: ``embed_motion`` and ``embed_text``.

    Args:
        model: a trained :class:`TextMotionEvaluator`.
        text_encoder: the sentence encoder its text side expects (MiniLM); cached.
    """

    name = "ours"

    def __init__(self, model: TextMotionEvaluator, text_encoder: Any) -> None:
        from simdiff.text.cache import CachedTextEncoder

        self.model = model.eval()
        self.text_encoder = text_encoder if isinstance(text_encoder, CachedTextEncoder) else CachedTextEncoder(text_encoder)

    @classmethod
    def load(cls, folder: str | os.PathLike[str], device: torch.device | str = "cpu", text_encoder: Any = None) -> "OurEvaluator":
        model = load_evaluator(folder, device)
        if text_encoder is None:
            from simdiff.text.base import load_text_encoder

            text_encoder = load_text_encoder(model.config.text_encoder, device)
        return cls(model, text_encoder)

    @property
    def normalizer(self) -> Normalizer:
        return Normalizer(self.model.mean.cpu().numpy(), self.model.std.cpu().numpy())

    @torch.no_grad()
    def embed_motion(self, features: Tensor, lengths: Tensor | Sequence[int]) -> np.ndarray:
        """(B, T, 263) raw features → (B, D) float64 numpy."""
        return self.model.embed_motion(features, lengths).double().cpu().numpy()

    @torch.no_grad()
    def embed_text(self, captions: Sequence[str], tokens: Sequence[Sequence[str]] | None = None) -> np.ndarray:
        """(B,) captions → (B, D) float64 numpy (``tokens`` unused)."""
        return self.model.embed_text_vectors(self.text_encoder.encode(list(captions))).double().cpu().numpy()
