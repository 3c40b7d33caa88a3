"""The reverse-diffusion loop shared by every sampler, with an x₀-replacement hook."""

from __future__ import annotations

from typing import TYPE_CHECKING, Callable, Iterable

import torch
from torch import Tensor

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
    scheduler: BaseScheduler,
    cond: Condition,
    num_frames: int,
    *,
    nfeats: int = 263,
    guidance: float = 2.5,
    batched_cfg: bool = True,
    generator: torch.Generator | None = None,
    x_init: Tensor | None = None,
    x0_hook: X0Hook | None = None,
    hook_timesteps: Iterable[int] | None = None,
    progress: Callable[[Iterable[Tensor]], Iterable[Tensor]] | None = None,
    env_guidance: float = 1.0,
    anchor: str = "adapters",
    anchor_alpha: float = 0.0,
    anchor_t_max: int | None = None,
    edit_t: int | None = None,
) -> Tensor:
    """Run the reverse process from pure noise; returns x₀ (B, num_frames, nfeats) normalised features.

    Args:
        denoiser: x₀-predicting network ``(x, t, cond) -> x̂₀``.
        scheduler: a DDPM/DDIM scheduler with timesteps set.
        cond: the condition (B items) on the target device.
        guidance: CFG scale s (1 = off).
        batched_cfg: one 2B forward per step instead of two B forwards.
        generator: for the initial noise and the sampler's noise.
        x0_hook: replaces x̂₀ at the timesteps in ``hook_timesteps`` (all when None).
        progress: optional iterable wrapper (e.g. ``tqdm``).
        env_guidance: environment guidance s_e (1 = off; :class:`GuidedDenoiser`), continuous φ only.
        anchor: what the text guidance runs on, ``"adapters"``, ``"backbone"`` or ``"reference"``
            (:class:`GuidedDenoiser`).
        anchor_alpha: adapter strength of the backbone or reference anchor's text guidance (0: the backbone alone).
        anchor_t_max: that anchor only at timesteps ≤ this, the adapters anchor above (None: every step).
        edit_t: the edit anchor's last timestep at the reference φ (None: its default; :class:`GuidedDenoiser`).
    """
    device = cond.text.device
    b = cond.batch_size
    x = x_init.to(device) if x_init is not None else torch.randn(
        (b, num_frames, nfeats), generator=generator, device=generator.device if generator else device
    ).to(device)
    model = GuidedDenoiser(denoiser, guidance, batched_cfg, env_scale=env_guidance, anchor=anchor,
                           anchor_alpha=anchor_alpha, anchor_t_max=anchor_t_max, edit_t=edit_t)
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
