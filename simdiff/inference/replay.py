"""Re-play an existing motion under another environment φ (``simdiff edit MOTION --gravity G --wind X Y``).

The motion's HumanML3D features are noised to the sampler's ``edit_t`` and denoised twice with the same noise: under
φ (the adapters, as :mod:`simdiff.diffusion.guidance` runs a generated motion off Earth) and under Earth without wind
(the backbone), each with the sampling's flight guidance (:mod:`simdiff.inference.flight_guidance`) at its own
gravity. Their difference, the model's answer to φ for this motion, is added to the motion itself: at Earth
without wind the motion comes back unchanged, and only what φ changes changes. A motion longer than the network's
196 frames runs in overlapping windows whose differences are cross-faded.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import torch
from torch import Tensor

from simdiff.diffusion.config import SamplingConfig
from simdiff.diffusion.guidance import REFERENCE_ENV, GuidedDenoiser
from simdiff.diffusion.sampling import make_scheduler
from simdiff.errors import SimdiffError
from simdiff.inference.flight_guidance import FlightGuide
from simdiff.motion.skeleton import MAX_FRAMES

if TYPE_CHECKING:
    from simdiff.inference.generator import MotionGenerator

OVERLAP: int = 40
"""Frames (2 s at 20 fps) two neighbouring windows share; their differences cross-fade linearly over them."""


def windows(frames: int, size: int = MAX_FRAMES, overlap: int = OVERLAP) -> list[tuple[int, int]]:
    """``[start, end)`` spans of at most ``size`` frames covering ``frames``, evenly spaced, the fewest with
    neighbours sharing at least ``overlap`` frames."""
    if frames <= size:
        return [(0, frames)]
    n = int(np.ceil((frames - overlap) / (size - overlap)))
    return [(int(s), int(s) + size) for s in np.round(np.linspace(0, frames - size, n))]


def blend_weights(frames: int, spans: Sequence[tuple[int, int]], ramp: int = OVERLAP) -> np.ndarray:
    """(len(spans), frames) float32 weights, summing to 1 on every frame: each span's weight rises linearly over
    its first ``ramp`` frames and falls over its last (not at the motion's ends), then all are normalised."""
    f = np.arange(frames, dtype=np.float64)
    w = np.zeros((len(spans), frames), dtype=np.float64)
    for i, (s, e) in enumerate(spans):
        rise = np.ones(frames) if s == 0 else (f - s + 1) / (ramp + 1)
        fall = np.ones(frames) if e == frames else (e - f) / (ramp + 1)
        w[i] = np.clip(np.minimum(rise, fall), 0.0, 1.0)
        w[i, :s] = w[i, e:] = 0.0
    return (w / w.sum(axis=0, keepdims=True)).astype(np.float32)


@dataclass(frozen=True)
class Replay:
    """What :func:`replay_features` gives: the edited features and the model's answer to φ it added.

    Attributes:
        features: (T, 263) un-normalised features of the motion under φ.
        difference: (T, 263) what φ changed (features under φ minus the input's); zero at Earth without wind.
    """

    features: np.ndarray
    difference: np.ndarray


def _edit_steps(config: SamplingConfig) -> list[int]:
    """The sampler's timesteps at or below ``config.edit_t``: where a re-play runs."""
    timesteps = make_scheduler(config.sampler, config.steps, config.eta).timesteps
    return [int(t) for t in timesteps if int(t) <= config.edit_t]


def replay_step_count(config: SamplingConfig, frames: int) -> int:
    """Network steps :func:`replay_features` takes for ``frames`` feature rows (two denoisings per window)."""
    return 2 * len(_edit_steps(config)) * len(windows(frames))


@torch.no_grad()
def _denoise_from(generator: MotionGenerator, x0: Tensor, config: SamplingConfig, text: Tensor | None, env: Tensor,
                  seed: int, progress: Callable[[Iterable[int]], Iterable[int]] | None = None) -> Tensor:
    """Noise normalised ``x0`` (1, T, F) to the first timestep at or below ``config.edit_t`` and run the guided
    sampler from there under ``env`` (1, 3) and ``text`` (1, text_dim) (None: the null text, no text guidance);
    x₀ (1, T, F) normalised."""
    from simdiff.model.condition import Condition

    scheduler = make_scheduler(config.sampler, config.steps, config.eta)
    steps = _edit_steps(config)
    if not steps:
        return x0
    gen = torch.Generator(device="cpu").manual_seed(int(seed))
    noise = torch.randn(x0.shape, generator=gen).to(x0.device)
    x = scheduler.add_noise(x0, noise, torch.tensor([steps[0]], device=x0.device))
    mask = torch.ones(x0.shape[:2], dtype=torch.bool, device=x0.device)
    if text is None:
        cond = Condition(text=torch.zeros(1, generator.config.backbone.text_dim, device=x0.device), frame_mask=mask,
                         alpha=config.alpha, env=env).unconditional()
    else:
        cond = Condition(text=text, frame_mask=mask, alpha=config.alpha, env=env)
    # edit_t 999 here: the motion itself is the Earth sample that the steps above edit_t follow in generate
    model = GuidedDenoiser(generator.network, config.guidance if text is not None else 1.0,
                           env_scale=config.env_guidance, edit_t=999, min_t=config.guidance_min_t)
    guide = FlightGuide(env[:, 0].tolist(), generator.mean, generator.std, config.flight_passes)
    for t in steps if progress is None else progress(steps):
        x0_hat = guide(model(x, torch.full((1,), t, dtype=torch.long, device=x.device), cond), t, x)
        x = scheduler.step(x0_hat, t, x, generator=gen).prev_sample
    return x


def replay_features(generator: MotionGenerator, features: np.ndarray, config: SamplingConfig, env: Sequence[float],
                    *, seed: int = 0, text: str = "",
                    progress: Callable[[Iterable[int]], Iterable[int]] | None = None) -> Replay:
    """The motion ``features`` (T, 263) un-normalised, re-played under φ = ``env`` (g_z m/s², w_x N, w_y N).

    Args:
        generator: a SimDiff generator with a continuous Sim Encoder.
        config: the sampling settings (sampler, steps, η, guidance, α, environment guidance, ``edit_t``).
        seed: the noise seed; window k uses seed + k.
        text: what the motion shows (optional); empty: the model's unconditional prediction.
        progress: optional wrapper of each denoising loop's timesteps (two loops per window).
    """
    if generator.config.sim is None or generator.config.sim.mode != "continuous":
        raise SimdiffError("re-playing a motion under φ needs a SimDiff model with a continuous Sim Encoder")
    feats = np.asarray(features, dtype=np.float32)
    if feats.ndim != 2 or feats.shape[1] != generator.config.backbone.nfeats:
        raise SimdiffError(f"features must be (T, {generator.config.backbone.nfeats}), got {feats.shape}")
    phi = torch.tensor([list(env)], dtype=torch.float32, device=generator.device)
    if phi.shape != (1, 3) or not bool(torch.isfinite(phi).all()):
        raise SimdiffError(f"env must be 3 finite numbers (g_z, w_x, w_y), got {list(env)}")
    if torch.equal(phi[0].cpu(), torch.tensor(REFERENCE_ENV)):
        return Replay(feats.copy(), np.zeros_like(feats))
    earth = torch.tensor([REFERENCE_ENV], dtype=torch.float32, device=generator.device)
    emb = generator.encode_text([text]) if text else None
    x = (torch.as_tensor(feats, device=generator.device) - generator.mean) / generator.std
    spans = windows(len(feats))
    diff = np.zeros_like(feats)
    for k, (weights, (s, e)) in enumerate(zip(blend_weights(len(feats), spans), spans)):
        x0 = x[None, s:e]
        moved = _denoise_from(generator, x0, config, emb, phi, seed + k, progress)
        still = _denoise_from(generator, x0, config, emb, earth, seed + k, progress)
        d = ((moved - still) * generator.std)[0].cpu().numpy()
        diff[s:e] += weights[s:e, None] * d
    out = feats + diff
    if not np.all(np.isfinite(out)):
        raise SimdiffError(f"re-playing under φ {list(env)} gave non-finite values; try settings nearer the model's "
                           "defaults")
    return Replay(out, diff)
