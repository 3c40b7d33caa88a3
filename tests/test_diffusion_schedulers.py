"""Schedulers: cosine schedule, respacing, DDPM/DDIM step formulas, numeric regression pins."""

from __future__ import annotations

import math

import numpy as np
import pytest
import torch

from simdiff.diffusion import DDIMScheduler, DDPMScheduler, make_scheduler
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


def _dummy_loop(scheduler, seed: int = 0) -> torch.Tensor:
    gen = torch.Generator().manual_seed(seed)
    x = torch.randn(2, 10, 263, generator=gen)
    for t in scheduler.timesteps:
        x = scheduler.step(0.8 * x, int(t), x, generator=gen).prev_sample
    return x


@pytest.mark.parametrize(
    "make, expected",
    [
        (lambda: make_scheduler("ddim", 50), 2614.9429),
        (lambda: make_scheduler("ddim", 50, eta=1.0), 1481.0883),
        (lambda: make_scheduler("ddpm"), 840.8746),
        (lambda: make_scheduler("ddpm", 100), 1238.5559),
    ],
)
def test_full_loop_regression(make, expected: float) -> None:
    assert _dummy_loop(make()).abs().sum().item() == pytest.approx(expected, rel=1e-4)


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
