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


def twin_difference_mse(pred: Tensor, x0: Tensor, mask: Tensor, paired: Tensor) -> Tensor:
    """MSE between predicted and true twin differences (items i and i + B/2) over the rows with ``paired`` set.

    pred, x0: (B, T, F); mask: (B, T) bool; paired: (B/2,) bool. 0 when no row is paired.
    """
    h = x0.shape[0] // 2
    if not bool(paired.any()):
        return pred.new_zeros(())
    keep = paired.nonzero().flatten()
    return masked_mse((pred[:h] - pred[h:])[keep], (x0[:h] - x0[h:])[keep], (mask[:h] & mask[h:])[keep])


def twin_drift_mse(pred: Tensor, x0: Tensor, mask: Tensor, paired: Tensor, channels: slice = slice(1, 3)) -> Tensor:
    """Squared error of the twins' difference in *mean* root velocity (items i and i + B/2, rows with ``paired``).

    For each paired twin, the root-velocity ``channels`` (default HumanML3D's heading-frame x, z: 1:3) are averaged
    over the frames valid in both, and the predicted difference of those means is compared with the true one;
    mean over twins and channels. A steady drift (wind pushing a walker) is a per-frame change of a few per cent of
    the root speed, buried in the frame-by-frame differences of two rollouts; averaged over the window it is the
    whole signal. pred, x0: (B, T, F) normalised features; mask: (B, T) bool; paired: (B/2,) bool. 0 when none.
    """
    h = x0.shape[0] // 2
    if not bool(paired.any()):
        return pred.new_zeros(())
    keep = paired.nonzero().flatten()
    m = (mask[:h] & mask[h:])[keep].to(pred.dtype)[..., None]  # (K, T, 1)
    frames = m.sum(dim=1).clamp_min(1.0)  # (K, 1)
    mean_diff = lambda x: ((x[:h] - x[h:])[keep][..., channels] * m).sum(dim=1) / frames  # noqa: E731
    return ((mean_diff(pred) - mean_diff(x0)) ** 2).mean()


def diffusion_prediction(denoiser: Denoiser, scheduler: BaseScheduler, x0: Tensor, cond: Condition,
                         generator: torch.Generator | None = None) -> Tensor:
    """Draw t ~ U{0..T−1} and ε ~ N(0, I), noise ``x0`` to x_t and return the predicted x₀ (B, T, F)."""
    b = x0.shape[0]
    gen_device = generator.device if generator is not None else x0.device
    t = torch.randint(0, scheduler.num_train_timesteps, (b,), generator=generator, device=gen_device).to(x0.device)
    noise = torch.randn(x0.shape, generator=generator, device=gen_device).to(x0.device)
    x_t = scheduler.add_noise(x0, noise, t)
    return denoiser(x_t, t, cond)


def diffusion_loss(denoiser: Denoiser, scheduler: BaseScheduler, x0: Tensor, cond: Condition, mask: Tensor,
                   generator: torch.Generator | None = None) -> Tensor:
    """One Monte-Carlo draw of the loss: t ~ U{0..T−1}, ε ~ N(0, I), predict x₀ from x_t.

    x0: (B, T, F) normalised, zero-padded; mask: (B, T) valid frames.
    """
    return masked_mse(diffusion_prediction(denoiser, scheduler, x0, cond, generator), x0, mask)
