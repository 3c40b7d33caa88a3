"""Our DDPM / DDIM samplers against diffusers' schedulers (an independent implementation).

Optional: ``pip install 'simdiff[parity]'``; skipped when diffusers is absent. Every step of a
whole trajectory is compared, with the same model outputs and the same noise. Tolerances
cover diffusers' float32 schedule against our float64 one.
"""

from __future__ import annotations

import pytest
import torch

diffusers = pytest.importorskip("diffusers")

from simdiff.diffusion.ddim import DDIMScheduler  # noqa: E402
from simdiff.diffusion.ddpm import DDPMScheduler  # noqa: E402

SCHEDULES = {"cosine": "squaredcos_cap_v2", "linear": "linear"}


def _theirs(cls, schedule: str, prediction: str, **kw):
    return cls(num_train_timesteps=1000, beta_schedule=SCHEDULES[schedule], prediction_type=prediction,
               clip_sample=False, **kw)


def _model(x: torch.Tensor, t: int) -> torch.Tensor:
    """A fixed nonlinear 'denoiser' (both samplers see the same outputs)."""
    return 0.8 * torch.tanh(x) + 0.01 * t / 1000


@pytest.mark.parametrize("schedule", ["cosine", "linear"])
def test_schedule_matches(schedule: str) -> None:
    ours = DDPMScheduler(beta_schedule=schedule)
    theirs = _theirs(diffusers.DDPMScheduler, schedule, "sample")
    assert torch.allclose(torch.from_numpy(ours.alphas_cumprod).float(), theirs.alphas_cumprod, rtol=1e-5, atol=1e-7)


@pytest.mark.parametrize("schedule, prediction, eta, steps", [
    ("cosine", "sample", 0.0, 50), ("cosine", "sample", 1.0, 50), ("cosine", "epsilon", 0.5, 20),
    ("linear", "sample", 0.0, 100),
])
def test_ddim_trajectory_matches_diffusers(schedule: str, prediction: str, eta: float, steps: int) -> None:
    ours = DDIMScheduler(beta_schedule=schedule, prediction_type=prediction, eta=eta)
    ours.set_timesteps(steps)
    theirs = _theirs(diffusers.DDIMScheduler, schedule, prediction, set_alpha_to_one=True, timestep_spacing="leading")
    theirs.set_timesteps(steps)
    assert theirs.timesteps.tolist() == ours.timesteps.tolist()  # MDM's 'ddimN' is diffusers' "leading" spacing
    gen = torch.Generator().manual_seed(0)
    a = b = torch.randn(2, 12, 263, generator=gen)
    for t in ours.timesteps.tolist():
        z = torch.randn(a.shape, generator=gen)
        a = ours.step(_model(a, t), t, a, noise=z).prev_sample
        b = theirs.step(_model(b, t), t, b, eta=eta, variance_noise=z).prev_sample
        assert torch.allclose(a, b, rtol=1e-4, atol=1e-4), t


@pytest.mark.parametrize("schedule, variance, steps", [
    ("cosine", "fixed_small", None), ("cosine", "fixed_large", 100), ("linear", "fixed_small", 100),
])
def test_ddpm_trajectory_matches_diffusers(schedule: str, variance: str, steps: int | None) -> None:
    ours = DDPMScheduler(beta_schedule=schedule, variance_type=variance)
    ours.set_timesteps(steps)
    theirs = _theirs(diffusers.DDPMScheduler, schedule, "sample", variance_type=variance)
    if steps is None:
        theirs.set_timesteps(1000)
    else:  # MDM respaces evenly, which diffusers takes as custom timesteps
        theirs.set_timesteps(timesteps=ours.timesteps.tolist())
    assert theirs.timesteps.tolist() == ours.timesteps.tolist()
    ga, gb = torch.Generator().manual_seed(1), torch.Generator().manual_seed(1)
    a = torch.randn(1, 8, 263, generator=ga)
    b = torch.randn(1, 8, 263, generator=gb)
    for t in ours.timesteps.tolist():  # both draw their noise from the generator, only while t > 0
        a = ours.step(_model(a, t), t, a, generator=ga).prev_sample
        b = theirs.step(_model(b, t), t, b, generator=gb).prev_sample
        assert torch.allclose(a, b, rtol=1e-4, atol=2e-4), t
