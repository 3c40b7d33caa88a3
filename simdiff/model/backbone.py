"""MDM-style transformer-encoder denoiser that predicts x₀.

Parameter names and shapes match the official MDM checkpoint (``input_process.poseEmbedding``,
``embed_timestep.time_embed.{0,2}``, ``embed_text``, ``seqTransEncoder.layers.i.*``,
``output_process.poseFinal``) so :func:`simdiff.model.checkpoint.load_mdm_state_dict` can
load it directly. Layers are post-LN (``norm_first=False``) like ``nn.TransformerEncoderLayer``;
the forward is written out so that Motion Adapters can be inserted after each sub-block.
"""

from __future__ import annotations

import math
from typing import Callable

import torch
from torch import Tensor, nn

from simdiff.model.condition import Condition
from simdiff.model.config import BackboneConfig

AdapterFn = Callable[[int, int, Tensor], Tensor]
"""``adapter(layer, position, h) -> h'``; position 0 after self-attention, 1 after feed-forward."""


def sinusoidal_table(max_len: int, dim: int) -> Tensor:
    """(max_len, dim) table: even columns sin(pos·div), odd columns cos(pos·div), as in MDM."""
    position = torch.arange(max_len, dtype=torch.float32)[:, None]
    div = torch.exp(torch.arange(0, dim, 2, dtype=torch.float32) * (-math.log(10000.0) / dim))
    table = torch.zeros(max_len, dim)
    table[:, 0::2] = torch.sin(position * div)
    table[:, 1::2] = torch.cos(position * div)
    return table


class InputProcess(nn.Module):
    """(B, T, nfeats) → (B, T, d) through ``poseEmbedding``."""

    def __init__(self, nfeats: int, dim: int) -> None:
        super().__init__()
        self.poseEmbedding = nn.Linear(nfeats, dim)

    def forward(self, x: Tensor) -> Tensor:
        return self.poseEmbedding(x)


class OutputProcess(nn.Module):
    """(B, T, d) → (B, T, nfeats) through ``poseFinal``."""

    def __init__(self, nfeats: int, dim: int) -> None:
        super().__init__()
        self.poseFinal = nn.Linear(dim, nfeats)

    def forward(self, h: Tensor) -> Tensor:
        return self.poseFinal(h)


class TimestepEmbedder(nn.Module):
    """Integer t → PE row → Linear–SiLU–Linear, giving (B, d)."""

    def __init__(self, dim: int) -> None:
        super().__init__()
        self.time_embed = nn.Sequential(nn.Linear(dim, dim), nn.SiLU(), nn.Linear(dim, dim))

    def forward(self, timesteps: Tensor, table: Tensor) -> Tensor:
        return self.time_embed(table[timesteps])


class EncoderLayer(nn.Module):
    """Post-LN transformer encoder layer with ``nn.TransformerEncoderLayer``'s parameter names."""

    def __init__(self, dim: int, heads: int, ff: int, dropout: float, activation: str) -> None:
        super().__init__()
        self.self_attn = nn.MultiheadAttention(dim, heads, dropout=dropout, batch_first=True)
        self.linear1 = nn.Linear(dim, ff)
        self.dropout = nn.Dropout(dropout)
        self.linear2 = nn.Linear(ff, dim)
        self.norm1 = nn.LayerNorm(dim)
        self.norm2 = nn.LayerNorm(dim)
        self.dropout1 = nn.Dropout(dropout)
        self.dropout2 = nn.Dropout(dropout)
        if activation not in ("gelu", "relu"):
            raise ValueError(f"activation must be gelu or relu, got {activation!r}")
        self.activation = nn.GELU() if activation == "gelu" else nn.ReLU()

    def forward(self, h: Tensor, key_padding_mask: Tensor | None, adapt: Callable[[int, Tensor], Tensor] | None) -> Tensor:
        """h: (B, S, d); key_padding_mask: (B, S) True where padded."""
        attn, _ = self.self_attn(h, h, h, key_padding_mask=key_padding_mask, need_weights=False)
        h = self.norm1(h + self.dropout1(attn))
        if adapt is not None:
            h = adapt(0, h)
        ff = self.linear2(self.dropout(self.activation(self.linear1(h))))
        h = self.norm2(h + self.dropout2(ff))
        if adapt is not None:
            h = adapt(1, h)
        return h


class _LayerStack(nn.Module):
    """Holds ``layers`` so names read ``seqTransEncoder.layers.i.*`` as in MDM."""

    def __init__(self, layers: list[EncoderLayer]) -> None:
        super().__init__()
        self.layers = nn.ModuleList(layers)


class MDMBackbone(nn.Module):
    """Transformer encoder over ``[condition token; frames]`` predicting x₀.

    Call with ``x_t`` (B, T, 263) normalised features (T ≤ 196 in practice), integer
    timesteps (B,) in ``[0, 1000)``, and a :class:`Condition`; returns x̂₀ (B, T, 263).
    """

    def __init__(self, config: BackboneConfig) -> None:
        super().__init__()
        c = config
        self.config = config
        self.register_buffer("pe", sinusoidal_table(c.max_len, c.latent_dim), persistent=False)
        self.input_process = InputProcess(c.nfeats, c.latent_dim)
        self.embed_timestep = TimestepEmbedder(c.latent_dim)
        self.embed_text = nn.Linear(c.text_dim, c.latent_dim)
        self.pe_dropout = nn.Dropout(c.dropout)
        self.seqTransEncoder = _LayerStack(
            [EncoderLayer(c.latent_dim, c.num_heads, c.ff_size, c.dropout, c.activation) for _ in range(c.num_layers)]
        )
        self.output_process = OutputProcess(c.nfeats, c.latent_dim)

    def condition_token(self, timesteps: Tensor, cond: Condition) -> Tensor:
        """(B, d) = time embedding + ``embed_text`` of the (possibly dropped) text."""
        text = cond.text
        if cond.uncond is not None:
            text = text * (~cond.uncond).to(text.dtype)[:, None]
        return self.embed_timestep(timesteps, self.pe) + self.embed_text(text)

    def forward(self, x: Tensor, timesteps: Tensor, cond: Condition, adapter: AdapterFn | None = None) -> Tensor:
        """x: (B, T, nfeats), timesteps: (B,) int64 → x̂₀ (B, T, nfeats)."""
        b, t, _ = x.shape
        if t + 1 > self.pe.shape[0]:
            raise ValueError(f"sequence of {t} frames exceeds the positional table ({self.pe.shape[0] - 1})")
        token = self.condition_token(timesteps, cond)
        h = torch.cat([token[:, None, :], self.input_process(x)], dim=1)
        h = self.pe_dropout(h + self.pe[: t + 1][None])
        key_padding_mask = None
        # a batch without padding takes the unmasked path: the same numbers, without the masked kernel's cost
        if self.config.mask_frames and cond.frame_mask is not None and not bool(cond.frame_mask.all()):
            valid = torch.cat([torch.ones(b, 1, dtype=torch.bool, device=x.device), cond.frame_mask.bool()], dim=1)
            key_padding_mask = ~valid
        for i, layer in enumerate(self.seqTransEncoder.layers):
            adapt = None if adapter is None else (lambda pos, hh, i=i: adapter(i, pos, hh))
            h = layer(h, key_padding_mask, adapt)
        return self.output_process(h[:, 1:])
