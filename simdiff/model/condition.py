"""The conditioning bundle a denoiser receives at every step."""

from __future__ import annotations

from dataclasses import dataclass, replace

import torch
from torch import Tensor


@dataclass
class Condition:
    """Everything but ``(x_t, t)`` that the network sees.

    Attributes:
        text: (B, text_dim) float32 text embeddings.
        uncond: (B,) bool; True drops the text (the null condition ``embed_text(0)``). None: keep all.
        frame_mask: (B, T) bool, True on valid frames; used for attention only when the
            backbone has ``mask_frames`` (and by the loss). None: all valid.
        env: (B, 3) float32 φ = (g_z m/s², w_x N, w_y N) for a continuous Sim Encoder.
        env_index: (B,) int64 environment category for a categorical Sim Encoder.
        alpha: adapter strength, a float or (B,) tensor (1 in training).
    """

    text: Tensor
    uncond: Tensor | None = None
    frame_mask: Tensor | None = None
    env: Tensor | None = None
    env_index: Tensor | None = None
    alpha: float | Tensor = 1.0

    @property
    def batch_size(self) -> int:
        return int(self.text.shape[0])

    def with_guidance_pair(self) -> "Condition":
        """Return the 2B-batch ``[conditional; unconditional]`` for one batched CFG forward.

        The text is dropped in the second half only; φ and α are kept in both halves
        (adapters stay active in both CFG passes, φ is never dropped).
        """
        return self.stacked(self.unconditional())

    def stacked(self, other: "Condition") -> "Condition":
        """The (B + B') condition of this batch followed by ``other``'s (α: both floats and equal, or tensors)."""

        def cat(a: Tensor | None, b: Tensor | None, name: str) -> Tensor | None:
            if (a is None) != (b is None):
                raise ValueError(f"cannot stack conditions: one has {name}, the other not")
            return None if a is None or b is None else torch.cat([a, b])

        def alphas(c: "Condition") -> Tensor:
            a = c.alpha
            return a if isinstance(a, Tensor) else torch.full((c.batch_size,), float(a), device=c.text.device)

        same = not isinstance(self.alpha, Tensor) and not isinstance(other.alpha, Tensor) and self.alpha == other.alpha
        keep = [c.uncond if c.uncond is not None else torch.zeros(c.batch_size, dtype=torch.bool, device=c.text.device)
                for c in (self, other)]
        return Condition(
            text=torch.cat([self.text, other.text]),
            uncond=None if self.uncond is None and other.uncond is None else torch.cat(keep),
            frame_mask=cat(self.frame_mask, other.frame_mask, "frame_mask"),
            env=cat(self.env, other.env, "env"),
            env_index=cat(self.env_index, other.env_index, "env_index"),
            alpha=self.alpha if same else torch.cat([alphas(self), alphas(other)]),
        )

    def select(self, rows: Tensor) -> "Condition":
        """The condition of the batch rows ``rows`` ((K,) int64 indices)."""

        def pick(value: Tensor | None) -> Tensor | None:
            return None if value is None else value[rows]

        alpha = self.alpha[rows] if isinstance(self.alpha, Tensor) else self.alpha
        return Condition(self.text[rows], pick(self.uncond), pick(self.frame_mask), pick(self.env),
                         pick(self.env_index), alpha)

    def unconditional(self) -> "Condition":
        """The same condition with every text dropped."""
        return replace(self, uncond=torch.ones(self.batch_size, dtype=torch.bool, device=self.text.device))

    def to(self, device: torch.device | str) -> "Condition":
        """Move every tensor to ``device``."""

        def mv(value: Tensor | None) -> Tensor | None:
            return None if value is None else value.to(device)

        alpha = self.alpha.to(device) if isinstance(self.alpha, Tensor) else self.alpha
        return Condition(mv(self.text), mv(self.uncond), mv(self.frame_mask), mv(self.env), mv(self.env_index), alpha)
