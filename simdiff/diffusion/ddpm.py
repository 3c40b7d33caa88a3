"""DDPM ancestral sampler (MDM's ``p_sample_loop``) for x₀-predicting models."""

from __future__ import annotations

import math

import torch
from torch import Tensor

from simdiff.diffusion.schedule import even_timesteps
from simdiff.diffusion.scheduler import BaseScheduler, SchedulerOutput, randn_like


class DDPMScheduler(BaseScheduler):
    """Ancestral sampling with the posterior q(x_{t−1} | x_t, x̂₀).

    Args:
        num_train_timesteps: T (1000).
        beta_schedule: ``"cosine"`` (MDM) or ``"linear"``.
        prediction_type: ``"sample"`` (x₀, MDM) or ``"epsilon"``.
        variance_type: ``"fixed_small"`` (β̃_t, MDM's ``sigma_small``) or ``"fixed_large"`` (β_t).
    """

    def __init__(self, num_train_timesteps: int = 1000, beta_schedule: str = "cosine", prediction_type: str = "sample",
                 variance_type: str = "fixed_small") -> None:
        super().__init__(num_train_timesteps, beta_schedule, prediction_type)
        if variance_type not in ("fixed_small", "fixed_large"):
            raise ValueError(f"variance_type must be fixed_small or fixed_large, got {variance_type!r}")
        self.config["variance_type"] = variance_type
        self.variance_type = variance_type

    def set_timesteps(self, num_inference_steps: int | None = None) -> None:
        """Use all T steps (None or T), or ``num_inference_steps`` evenly respaced ones."""
        n = num_inference_steps or self.num_train_timesteps
        self._keep(even_timesteps(self.num_train_timesteps, n) if n != self.num_train_timesteps else list(range(n)))

    def _variance(self, timestep: int) -> float:
        """Per-step variance; at the first kept step it is clipped to the next step's (never used: no noise at t=0)."""
        i = self._index[int(timestep)]
        if i == 0 and len(self._kept) > 1:
            timestep = self._kept[1]
        abar, prev = self._abar_pair(timestep)
        beta = 1.0 - abar / prev
        if self.variance_type == "fixed_large":
            return beta
        return beta * (1.0 - prev) / (1.0 - abar)

    def step(self, model_output: Tensor, timestep: int, sample: Tensor, generator: torch.Generator | None = None,
             noise: Tensor | None = None) -> SchedulerOutput:
        """x_t → x_{t_prev}: posterior mean ``c1·x̂₀ + c2·x_t`` plus noise when t is not the first kept step.

        Args:
            model_output: the network output at ``timestep`` (x̂₀ or ε), (B, T, F).
            timestep: the current (original-scale) integer t.
            sample: x_t (B, T, F).
            generator: for the noise draw; ``noise`` overrides it.
        """
        abar, prev = self._abar_pair(timestep)
        beta = 1.0 - abar / prev
        x0 = self._to_x0(model_output, timestep, sample)
        c1 = beta * math.sqrt(prev) / (1.0 - abar)
        c2 = (1.0 - prev) * math.sqrt(1.0 - beta) / (1.0 - abar)
        mean = c1 * x0 + c2 * sample
        if self._index[int(timestep)] > 0:
            z = noise if noise is not None else randn_like(sample, generator)
            mean = mean + math.sqrt(self._variance(timestep)) * z
        return SchedulerOutput(prev_sample=mean, pred_original_sample=x0)
