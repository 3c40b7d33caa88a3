"""Shared pieces of the samplers: the step output, noise draws, and a base with ``add_noise``."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import torch
from torch import Tensor

from simdiff.diffusion.schedule import make_betas


@dataclass
class SchedulerOutput:
    """What :meth:`step` returns.

    Attributes:
        prev_sample: x_{t_prev} (B, T, 263).
        pred_original_sample: the x̂₀ (B, T, 263) the step used.
    """

    prev_sample: Tensor
    pred_original_sample: Tensor


def randn_like(sample: Tensor, generator: torch.Generator | None) -> Tensor:
    """Standard normal noise shaped like ``sample``, drawn on the generator's device."""
    device = generator.device if generator is not None else sample.device
    return torch.randn(sample.shape, generator=generator, device=device, dtype=sample.dtype).to(sample.device)


class BaseScheduler:
    """Training-time quantities common to every sampler (float64 schedule, float32 outputs).

    Subclasses implement ``set_timesteps`` and ``step``. Init options are kept in
    ``self.config`` (plain values) so a scheduler can be rebuilt with ``cls(**config)``.
    """

    def __init__(self, num_train_timesteps: int = 1000, beta_schedule: str = "cosine", prediction_type: str = "sample") -> None:
        if prediction_type not in ("sample", "epsilon"):
            raise ValueError(f"prediction_type must be sample or epsilon, got {prediction_type!r}")
        self.config: dict[str, Any] = dict(
            num_train_timesteps=num_train_timesteps, beta_schedule=beta_schedule, prediction_type=prediction_type
        )
        self.num_train_timesteps = num_train_timesteps
        self.prediction_type = prediction_type
        self.betas = make_betas(beta_schedule, num_train_timesteps)
        self.alphas_cumprod = np.cumprod(1.0 - self.betas)
        self._sqrt_abar = torch.from_numpy(np.sqrt(self.alphas_cumprod)).float()
        self._sqrt_one_minus_abar = torch.from_numpy(np.sqrt(1.0 - self.alphas_cumprod)).float()
        self.timesteps: Tensor = torch.arange(num_train_timesteps - 1, -1, -1)
        self._kept: list[int] = list(range(num_train_timesteps))
        self._index: dict[int, int] = {t: i for i, t in enumerate(self._kept)}

    def _keep(self, kept: list[int]) -> None:
        self._kept = sorted(kept)
        self._index = {t: i for i, t in enumerate(self._kept)}
        self.timesteps = torch.tensor(self._kept[::-1], dtype=torch.long)

    def _abar_pair(self, timestep: int) -> tuple[float, float]:
        """(ᾱ_t, ᾱ_prev) for a kept timestep, ᾱ_prev = 1 before the first kept step."""
        try:
            i = self._index[int(timestep)]
        except KeyError:
            raise ValueError(f"timestep {timestep} is not one of this scheduler's timesteps") from None
        abar = float(self.alphas_cumprod[self._kept[i]])
        prev = float(self.alphas_cumprod[self._kept[i - 1]]) if i > 0 else 1.0
        return abar, prev

    def _to_x0(self, model_output: Tensor, timestep: int, sample: Tensor) -> Tensor:
        if self.prediction_type == "sample":
            return model_output
        abar = float(self.alphas_cumprod[int(timestep)])
        return (sample - (1 - abar) ** 0.5 * model_output) / abar**0.5

    def add_noise(self, original_samples: Tensor, noise: Tensor, timesteps: Tensor) -> Tensor:
        """q(x_t | x₀): √ᾱ_t·x₀ + √(1−ᾱ_t)·ε for (B, T, F) samples and (B,) int timesteps."""
        t = timesteps.to("cpu").long()
        a = self._sqrt_abar[t].to(original_samples.device, original_samples.dtype)
        s = self._sqrt_one_minus_abar[t].to(original_samples.device, original_samples.dtype)
        shape = (-1,) + (1,) * (original_samples.dim() - 1)
        return a.reshape(shape) * original_samples + s.reshape(shape) * noise
