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
        b = self.batch_size
        keep = self.uncond if self.uncond is not None else torch.zeros(b, dtype=torch.bool, device=self.text.device)
        uncond = torch.cat([keep, torch.ones_like(keep)])

        def twice(value: Tensor | None) -> Tensor | None:
            return None if value is None else torch.cat([value, value])

        alpha = twice(self.alpha) if isinstance(self.alpha, Tensor) else self.alpha
        return Condition(
            text=torch.cat([self.text, self.text]),
            uncond=uncond,
            frame_mask=twice(self.frame_mask),
            env=twice(self.env),
            env_index=twice(self.env_index),
            alpha=alpha,
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
