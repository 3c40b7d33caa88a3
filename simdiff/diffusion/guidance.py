"""Classifier-free guidance on the x₀ prediction: x̃₀ = x₀(∅) + s·(x₀(c) − x₀(∅))."""

from __future__ import annotations

from typing import TYPE_CHECKING, Callable

import torch
from torch import Tensor

if TYPE_CHECKING:
    from simdiff.model.condition import Condition

Denoiser = Callable[[Tensor, Tensor, "Condition"], Tensor]
"""``denoiser(x_t (B,T,F), t (B,) int64, cond) -> x̂₀ (B,T,F)``."""


class GuidedDenoiser:
    """Wrap a denoiser with classifier-free guidance.

    Args:
        denoiser: the network (MDMBackbone or SimDiffNet, or anything with the same call).
        scale: s; 1 disables guidance (one conditional pass).
        batched: run the conditional and unconditional passes as one 2B forward (default)
            instead of two B forwards. The text is dropped in the second half only; φ/α are kept.
    """

    def __init__(self, denoiser: Denoiser, scale: float = 2.5, batched: bool = True) -> None:
        self.denoiser = denoiser
        self.scale = float(scale)
        self.batched = batched

    def __call__(self, x: Tensor, timesteps: Tensor, cond: Condition) -> Tensor:
        """x: (B, T, F), timesteps: (B,) → guided x̂₀ (B, T, F)."""
        if self.scale == 1.0:
            return self.denoiser(x, timesteps, cond)
        if self.batched:
            out = self.denoiser(torch.cat([x, x]), torch.cat([timesteps, timesteps]), cond.with_guidance_pair())
            cond_out, uncond_out = out.chunk(2)
        else:
            cond_out = self.denoiser(x, timesteps, cond)
            uncond_out = self.denoiser(x, timesteps, cond.unconditional())
        return uncond_out + self.scale * (cond_out - uncond_out)
