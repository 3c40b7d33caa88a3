"""DDIM sampler with MDM's ``'ddimN'`` respacing (``ddim50`` → t ∈ {0, 20, …, 980}) and η."""

from __future__ import annotations

import math

import torch
from torch import Tensor

from simdiff.diffusion.schedule import ddim_timesteps
from simdiff.diffusion.scheduler import BaseScheduler, SchedulerOutput, randn_like


class DDIMScheduler(BaseScheduler):
    """Deterministic (η = 0) or stochastic DDIM (Song et al. 2021, eq. 12).

    Args:
        num_train_timesteps: T (1000).
        beta_schedule: ``"cosine"`` (MDM) or ``"linear"``.
        prediction_type: ``"sample"`` (x₀) or ``"epsilon"``.
        eta: η, the noise scale (0 deterministic, 1 ≈ DDPM).
    """

    def __init__(self, num_train_timesteps: int = 1000, beta_schedule: str = "cosine", prediction_type: str = "sample",
                 eta: float = 0.0) -> None:
        super().__init__(num_train_timesteps, beta_schedule, prediction_type)
        self.config["eta"] = eta
        self.eta = eta
        self.set_timesteps(50)

    def set_timesteps(self, num_inference_steps: int = 50) -> None:
        """Keep the ``'ddim{num_inference_steps}'`` steps; ``self.timesteps`` is descending."""
        self._keep(ddim_timesteps(self.num_train_timesteps, num_inference_steps))

    def step(self, model_output: Tensor, timestep: int, sample: Tensor, eta: float | None = None,
             generator: torch.Generator | None = None, noise: Tensor | None = None) -> SchedulerOutput:
        """x_t → x_{t_prev}.

        ε̂ = (√(1/ᾱ_t)·x_t − x̂₀)/√(1/ᾱ_t − 1);
        x_prev = √ᾱ_prev·x̂₀ + √(1 − ᾱ_prev − σ²)·ε̂ + σ·z,
        σ = η·√((1−ᾱ_prev)/(1−ᾱ_t))·√(1 − ᾱ_t/ᾱ_prev).
        """
        eta = self.eta if eta is None else eta
        abar, prev = self._abar_pair(timestep)
        x0 = self._to_x0(model_output, timestep, sample)
        eps = (math.sqrt(1.0 / abar) * sample - x0) / math.sqrt(1.0 / abar - 1.0)
        sigma = eta * math.sqrt((1.0 - prev) / (1.0 - abar)) * math.sqrt(1.0 - abar / prev)
        out = math.sqrt(prev) * x0 + math.sqrt(max(1.0 - prev - sigma**2, 0.0)) * eps
        if sigma > 0 and self._index[int(timestep)] > 0:
            z = noise if noise is not None else randn_like(sample, generator)
            out = out + sigma * z
        return SchedulerOutput(prev_sample=out, pred_original_sample=x0)
