"""The reverse-diffusion loop shared by every sampler, with an x₀-replacement hook."""

from __future__ import annotations

from typing import TYPE_CHECKING, Callable, Iterable

import torch
from torch import Tensor

from simdiff.diffusion.config import SamplingConfig
from simdiff.diffusion.ddim import DDIMScheduler
from simdiff.diffusion.ddpm import DDPMScheduler
from simdiff.diffusion.guidance import Denoiser, GuidedDenoiser
from simdiff.diffusion.scheduler import BaseScheduler
from simdiff.errors import SimdiffError

if TYPE_CHECKING:
    from simdiff.model.condition import Condition

X0Hook = Callable[[Tensor, int, Tensor], Tensor]
"""``hook(x0_pred (B,T,F), t, x_t (B,T,F)) -> x0' (B,T,F)``: replaces the x₀ prediction at chosen t
(PhysDiff's simulator projection); the step then uses x0' for the posterior / DDIM update."""


def make_scheduler(name: str, steps: int | None = None, eta: float = 0.0, num_train_timesteps: int = 1000) -> BaseScheduler:
    """``ddpm`` (``steps`` None → all T) or ``ddim`` (``steps`` default 50), timesteps set."""
    if name == "ddpm":
        scheduler: BaseScheduler = DDPMScheduler(num_train_timesteps)
        scheduler.set_timesteps(steps)  # type: ignore[attr-defined]
    elif name == "ddim":
        scheduler = DDIMScheduler(num_train_timesteps, eta=eta)
        scheduler.set_timesteps(steps or 50)  # type: ignore[attr-defined]
    else:
        raise SimdiffError(f"unknown sampler {name!r}; choose ddpm or ddim")
    return scheduler


@torch.no_grad()
def sample(
    denoiser: Denoiser,
    config: SamplingConfig,
    cond: Condition,
    num_frames: int,
    *,
    nfeats: int = 263,
    batched_cfg: bool = True,
    generator: torch.Generator | None = None,
    x_init: Tensor | None = None,
    x0_hook: X0Hook | None = None,
    hook_timesteps: Iterable[int] | None = None,
    progress: Callable[[Iterable[Tensor]], Iterable[Tensor]] | None = None,
) -> Tensor:
    """Run the reverse process from pure noise; returns x₀ (B, num_frames, nfeats) normalised features.

    Args:
        denoiser: x₀-predicting network ``(x, t, cond) -> x̂₀``.
        config: sampler, steps, η, text guidance, environment guidance and ``edit_t`` (:class:`GuidedDenoiser`);
            its ``alpha`` and ``foot_lock`` are the caller's (they live in ``cond`` and the post-process).
        cond: the condition (B items) on the target device.
        batched_cfg: one 2B forward per step instead of two B forwards.
        generator: for the initial noise and the sampler's noise.
        x0_hook: replaces x̂₀ at the timesteps in ``hook_timesteps`` (all when None).
        progress: optional iterable wrapper (e.g. ``tqdm``).
    """
    device = cond.text.device
    b = cond.batch_size
    x = x_init.to(device) if x_init is not None else torch.randn(
        (b, num_frames, nfeats), generator=generator, device=generator.device if generator else device
    ).to(device)
    scheduler = make_scheduler(config.sampler, config.steps, config.eta)
    model = GuidedDenoiser(denoiser, config.guidance, batched_cfg, env_scale=config.env_guidance, edit_t=config.edit_t,
                           min_t=config.guidance_min_t)
    hooked = None if hook_timesteps is None else {int(t) for t in hook_timesteps}
    steps: Iterable[Tensor] = scheduler.timesteps
    if progress is not None:
        steps = progress(steps)
    for t in steps:
        ti = int(t)
        x0 = model(x, torch.full((b,), ti, dtype=torch.long, device=device), cond)
        if x0_hook is not None and (hooked is None or ti in hooked):
            x0 = x0_hook(x0, ti, x)
        x = scheduler.step(x0, ti, x, generator=generator).prev_sample
    return x
