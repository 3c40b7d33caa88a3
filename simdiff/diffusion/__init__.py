"""Gaussian diffusion for x₀-predicting motion models: schedule, DDPM, DDIM, CFG, loss, sampling loop."""

from simdiff.diffusion.ddim import DDIMScheduler
from simdiff.diffusion.ddpm import DDPMScheduler
from simdiff.diffusion.guidance import GuidedDenoiser
from simdiff.diffusion.losses import diffusion_loss, lengths_to_mask, masked_mse
from simdiff.diffusion.sampling import X0Hook, make_scheduler, sample
from simdiff.diffusion.scheduler import SchedulerOutput

__all__ = [
    "DDIMScheduler", "DDPMScheduler", "GuidedDenoiser", "SchedulerOutput",
    "X0Hook", "diffusion_loss", "lengths_to_mask", "masked_mse", "make_scheduler", "sample",
]
