"""Noise schedules and MDM's timestep respacing (float64, computed once on CPU)."""

from __future__ import annotations

import math

import numpy as np

from simdiff.errors import SimdiffError


def cosine_alphas_cumprod(num_timesteps: int = 1000, s: float = 0.008) -> np.ndarray:
    """ᾱ_t for t = 0..T−1 of the cosine schedule, via the clipped betas.

    ᾱ(u) = cos²(((u/T + s)/(1 + s))·π/2), β_t = min(1 − ᾱ(t+1)/ᾱ(t), 0.999), ᾱ_t = Π_{i≤t}(1 − β_i).
    """
    return np.cumprod(1.0 - cosine_betas(num_timesteps, s))


def cosine_betas(num_timesteps: int = 1000, s: float = 0.008, max_beta: float = 0.999) -> np.ndarray:
    """(T,) float64 β_t of the cosine schedule (Nichol & Dhariwal), as MDM uses."""

    def abar(u: float) -> float:
        return math.cos((u / num_timesteps + s) / (1 + s) * math.pi / 2) ** 2

    return np.array([min(1 - abar(i + 1) / abar(i), max_beta) for i in range(num_timesteps)], dtype=np.float64)


def linear_betas(num_timesteps: int = 1000) -> np.ndarray:
    """(T,) float64 β_t of the DDPM linear schedule scaled to T steps."""
    scale = 1000 / num_timesteps
    return np.linspace(scale * 1e-4, scale * 0.02, num_timesteps, dtype=np.float64)


def make_betas(schedule: str, num_timesteps: int) -> np.ndarray:
    """β_t for ``schedule`` in {``cosine``, ``linear``}."""
    if schedule == "cosine":
        return cosine_betas(num_timesteps)
    if schedule == "linear":
        return linear_betas(num_timesteps)
    raise SimdiffError(f"unknown noise schedule {schedule!r}; choose cosine or linear")


def ddim_timesteps(num_timesteps: int, num_steps: int) -> list[int]:
    """MDM's ``'ddimN'`` respacing: the smallest integer stride s with ``len(range(0, T, s)) == N``.

    ``ddim_timesteps(1000, 50)`` → [0, 20, …, 980]. Ascending order.
    """
    if not 1 <= num_steps <= num_timesteps:
        raise SimdiffError(f"steps must lie in [1, {num_timesteps}], got {num_steps}")
    for stride in range(1, num_timesteps + 1):
        if len(range(0, num_timesteps, stride)) == num_steps:
            return list(range(0, num_timesteps, stride))
    raise SimdiffError(f"cannot respace {num_timesteps} steps to exactly {num_steps} with an integer stride")


def even_timesteps(num_timesteps: int, num_steps: int) -> list[int]:
    """Evenly spread ``num_steps`` kept steps (MDM's integer-count respacing for one section)."""
    if not 1 <= num_steps <= num_timesteps:
        raise SimdiffError(f"steps must lie in [1, {num_timesteps}], got {num_steps}")
    if num_steps == 1:
        return [0]
    frac = (num_timesteps - 1) / (num_steps - 1)
    return sorted({int(round(i * frac)) for i in range(num_steps)})


def respaced_alphas_cumprod(alphas_cumprod: np.ndarray, kept: list[int]) -> tuple[np.ndarray, np.ndarray]:
    """ᾱ at the kept steps and the matching "previous" ᾱ (1.0 before the first)."""
    abar = alphas_cumprod[np.asarray(kept)]
    prev = np.concatenate([[1.0], abar[:-1]])
    return abar, prev
