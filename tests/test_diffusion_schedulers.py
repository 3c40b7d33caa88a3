"""Schedulers: cosine schedule, respacing, DDPM/DDIM step formulas, whole loops against closed forms.

Trajectory parity with diffusers: tests/test_diffusion_parity.py (optional dependency).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import torch

from simdiff.diffusion.ddim import DDIMScheduler
from simdiff.diffusion.ddpm import DDPMScheduler
from simdiff.diffusion.sampling import make_scheduler
from simdiff.diffusion.schedule import cosine_betas, ddim_timesteps, even_timesteps
from simdiff.errors import SimdiffError


def abar_formula(t: float, T: int = 1000) -> float:
    return math.cos(((t / T + 0.008) / 1.008) * math.pi / 2) ** 2


def test_cosine_schedule_values() -> None:
    betas = cosine_betas(1000)
    assert betas.dtype == np.float64 and betas.shape == (1000,)
    assert betas[0] == pytest.approx(1 - abar_formula(1) / abar_formula(0), rel=1e-12)
    assert betas[-1] == 0.999  # clipped
    s = DDPMScheduler()
    assert s.alphas_cumprod[499] == pytest.approx(0.4938435904406382, rel=1e-12)
    assert s.alphas_cumprod[980] == pytest.approx(8.765293819602857e-4, rel=1e-10)


def test_mdm_ddim50_respacing() -> None:
    assert ddim_timesteps(1000, 50) == list(range(0, 1000, 20))
    s = DDIMScheduler()
    s.set_timesteps(50)
    assert s.timesteps[0] == 980 and s.timesteps[-1] == 0 and len(s.timesteps) == 50
    s.set_timesteps(10)
    assert s.timesteps.tolist() == list(range(900, -1, -100))
    with pytest.raises(SimdiffError):
        ddim_timesteps(1000, 0)
    assert even_timesteps(1000, 5) == [0, 250, 500, 749, 999]


def test_add_noise() -> None:
    s = DDPMScheduler()
    x0, eps = torch.ones(2, 3, 263), torch.full((2, 3, 263), 2.0)
    out = s.add_noise(x0, eps, torch.tensor([0, 499]))
    a = math.sqrt(s.alphas_cumprod[499])
    assert torch.allclose(out[1], torch.full((3, 263), a + 2 * math.sqrt(1 - a * a)))


def test_ddpm_step_matches_posterior_formula() -> None:
    s = DDPMScheduler()
    t = 420
    ab, prev = s.alphas_cumprod[t], s.alphas_cumprod[t - 1]
    beta = s.betas[t]
    var = beta * (1 - prev) / (1 - ab)
    assert s._variance(t) == pytest.approx(var, rel=1e-10)
    assert s._variance(t) == pytest.approx(0.0024450603111364684, rel=1e-10)
    x0, xt, z = torch.randn(1, 4, 263), torch.randn(1, 4, 263), torch.randn(1, 4, 263)
    c1 = beta * math.sqrt(prev) / (1 - ab)
    c2 = (1 - prev) * math.sqrt(1 - beta) / (1 - ab)
    out = s.step(x0, t, xt, noise=z).prev_sample
    assert torch.allclose(out, c1 * x0 + c2 * xt + math.sqrt(var) * z, atol=1e-6)
    # t = 0: the posterior mean is x̂₀ and no noise is added.
    assert torch.allclose(s.step(x0, 0, xt, noise=z).prev_sample, x0, atol=1e-6)


def test_ddim_step_matches_eq12() -> None:
    s = DDIMScheduler(eta=0.5)
    t, tp = 500, 480
    ab, prev = s.alphas_cumprod[t], s.alphas_cumprod[tp]
    x0, xt, z = torch.randn(2, 5, 263), torch.randn(2, 5, 263), torch.randn(2, 5, 263)
    eps = (math.sqrt(1 / ab) * xt - x0) / math.sqrt(1 / ab - 1)
    sigma = 0.5 * math.sqrt((1 - prev) / (1 - ab)) * math.sqrt(1 - ab / prev)
    expected = math.sqrt(prev) * x0 + math.sqrt(1 - prev - sigma**2) * eps + sigma * z
    assert torch.allclose(s.step(x0, t, xt, noise=z).prev_sample, expected, atol=1e-5)
    with pytest.raises(ValueError):
        s.step(x0, 501, xt)


def test_ddim_with_an_oracle_recovers_x0() -> None:
    target = torch.randn(1, 8, 263, generator=torch.Generator().manual_seed(1))
    s = make_scheduler("ddim", 50)
    x = torch.randn(1, 8, 263)
    for t in s.timesteps:
        x = s.step(target, int(t), x).prev_sample
    assert torch.allclose(x, target, atol=1e-5)


def _abar_closed_form(T: int = 1000) -> list[float]:
    """ᾱ_t of the clipped cosine schedule from its definition (independent of simdiff.diffusion.schedule)."""
    out, prod = [], 1.0
    for i in range(T):
        prod *= 1 - min(1 - abar_formula(i + 1, T) / abar_formula(i, T), 0.999)
        out.append(prod)
    return out


def _linear_loop(scheduler, c: float, n: int = 20000, seed: int = 0) -> torch.Tensor:
    """Run the sampler with the linear denoiser x̂₀ = c·x_t from x_T ~ N(0, I)."""
    gen = torch.Generator().manual_seed(seed)
    x = torch.randn(1, n, 1, generator=gen, dtype=torch.float64)
    for t in scheduler.timesteps:
        x = scheduler.step(c * x, int(t), x, generator=gen).prev_sample
    return x


def _gains(kept: list[int], c: float, eta: float | None) -> tuple[float, float]:
    """Closed form of a whole loop with x̂₀ = c·x_t: every step is x ← a·x + s·z, so x₀ ~ N(0, v).

    Returns (Π a, v) for DDIM (``eta``) or DDPM (``eta=None``, the posterior with β̃).
    """
    abar = _abar_closed_form()
    gain, var = 1.0, 1.0
    for i in range(len(kept) - 1, -1, -1):
        ab = abar[kept[i]]
        prev = abar[kept[i - 1]] if i > 0 else 1.0
        if eta is None:
            beta = 1 - ab / prev
            a = beta * math.sqrt(prev) / (1 - ab) * c + (1 - prev) * math.sqrt(1 - beta) / (1 - ab)
            s2 = beta * (1 - prev) / (1 - ab) if i > 0 else 0.0
        else:
            sig = eta * math.sqrt((1 - prev) / (1 - ab) * (1 - ab / prev))
            eps_gain = (1 / math.sqrt(ab) - c) / math.sqrt(1 / ab - 1)  # ε̂ = eps_gain·x_t
            a = math.sqrt(prev) * c + math.sqrt(max(1 - prev - sig**2, 0.0)) * eps_gain
            s2 = sig**2 if i > 0 else 0.0
        gain *= a
        var = a * a * var + s2
    return gain, var


def test_deterministic_ddim_loop_equals_its_closed_form() -> None:
    s = make_scheduler("ddim", 50)
    gen = torch.Generator().manual_seed(0)
    x = torch.randn(1, 64, 263, generator=gen, dtype=torch.float64)
    out = x.clone()
    for t in s.timesteps:
        out = s.step(0.8 * out, int(t), out).prev_sample
    gain, _ = _gains(list(range(0, 1000, 20)), 0.8, eta=0.0)
    assert torch.allclose(out, gain * x, rtol=1e-9, atol=1e-12)


@pytest.mark.parametrize("name, steps, eta", [("ddim", 50, 1.0), ("ddim", 20, 0.5), ("ddpm", None, None), ("ddpm", 100, None)])
def test_stochastic_loop_has_the_closed_form_variance(name: str, steps: int | None, eta: float | None) -> None:
    s = make_scheduler(name, steps, eta=eta or 0.0)
    kept = sorted(s.timesteps.tolist())
    _, var = _gains(kept, 0.5, eta)  # with c = 0.5, β̃ and β (fixed_large) give clearly different variances
    x = _linear_loop(s, 0.5)
    n = x.numel()
    assert abs(x.mean().item()) < 5 * math.sqrt(var / n)
    assert x.var().item() == pytest.approx(var, rel=5 * math.sqrt(2 / n))  # 5 σ of a variance estimate


def test_scheduler_config_rebuilds() -> None:
    s = DDIMScheduler(eta=0.3)
    assert DDIMScheduler(**s.config).config == s.config
    assert DDPMScheduler(**DDPMScheduler(variance_type="fixed_large").config).variance_type == "fixed_large"
    with pytest.raises(SimdiffError):
        make_scheduler("plms")


def test_epsilon_prediction_equivalent() -> None:
    s_x0, s_eps = DDIMScheduler(), DDIMScheduler(prediction_type="epsilon")
    t = 300
    ab = s_x0.alphas_cumprod[t]
    x0, eps = torch.randn(1, 3, 263), torch.randn(1, 3, 263)
    xt = math.sqrt(ab) * x0 + math.sqrt(1 - ab) * eps
    assert torch.allclose(s_x0.step(x0, t, xt).prev_sample, s_eps.step(eps, t, xt).prev_sample, atol=1e-4)
