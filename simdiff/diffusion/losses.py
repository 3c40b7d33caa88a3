"""Training loss: x₀-prediction masked MSE (MDM's ``rot_mse``)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import torch
from torch import Tensor

from simdiff.diffusion.guidance import Denoiser
from simdiff.diffusion.scheduler import BaseScheduler

if TYPE_CHECKING:
    from simdiff.model.condition import Condition


def lengths_to_mask(lengths: Tensor, max_len: int) -> Tensor:
    """(B,) lengths → (B, max_len) bool, True on valid frames."""
    return torch.arange(max_len, device=lengths.device)[None, :] < lengths[:, None]


def masked_mse(pred: Tensor, target: Tensor, mask: Tensor) -> Tensor:
    """Σ squared error over (valid frames × features) / (n_valid × F) per sample, mean over the batch.

    pred, target: (B, T, F); mask: (B, T) bool.
    """
    m = mask.to(pred.dtype)[..., None]
    per_sample = ((pred - target) ** 2 * m).sum(dim=(1, 2)) / (m.sum(dim=(1, 2)) * pred.shape[-1]).clamp_min(1.0)
    return per_sample.mean()


def diffusion_loss(denoiser: Denoiser, scheduler: BaseScheduler, x0: Tensor, cond: Condition, mask: Tensor,
                   generator: torch.Generator | None = None) -> Tensor:
    """One Monte-Carlo draw of the loss: t ~ U{0..T−1}, ε ~ N(0, I), predict x₀ from x_t.

    x0: (B, T, F) normalised, zero-padded; mask: (B, T) valid frames.
    """
    b = x0.shape[0]
    gen_device = generator.device if generator is not None else x0.device
    t = torch.randint(0, scheduler.num_train_timesteps, (b,), generator=generator, device=gen_device).to(x0.device)
    noise = torch.randn(x0.shape, generator=generator, device=gen_device).to(x0.device)
    x_t = scheduler.add_noise(x0, noise, t)
    return masked_mse(denoiser(x_t, t, cond), x0, mask)
