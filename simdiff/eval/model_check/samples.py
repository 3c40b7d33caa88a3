"""Prompt sets: fixed prompts × seeds generated in fixed batches, so that every φ sees the same noise.

A set is a list of :class:`PromptBatch` (one prompt, one seed, ``count`` samples). Each batch is
one ``generate`` call with its own noise seed, so generating the same set under another φ gives,
sample for sample, the motion "with the same seed".
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np


@dataclass(frozen=True)
class PromptBatch:
    """One generation call: ``count`` samples of ``prompt`` with noise seed ``noise_seed``."""

    prompt: str
    prompt_index: int
    seed: int
    count: int

    @property
    def noise_seed(self) -> int:
        return int(self.seed) * 1_000_003 + 7919 * int(self.prompt_index) + 17


def plan_batches(prompts: Sequence[str], samples: int, seeds: Sequence[int]) -> list[PromptBatch]:
    """``samples`` per prompt split as evenly as possible over ``seeds`` (empty shares dropped)."""
    shares = [len(part) for part in np.array_split(np.arange(samples), len(seeds))]
    return [PromptBatch(p, i, int(s), n) for i, p in enumerate(prompts) for s, n in zip(seeds, shares) if n > 0]


def units(batches: Sequence[PromptBatch]) -> list[str]:
    """One id per sample, ``prompt#seed#k`` in generation order."""
    return [f"{b.prompt}#{b.seed}#{k}" for b in batches for k in range(b.count)]


def generate_set_flags(generator: Any, batches: Sequence[PromptBatch], length: int, *, env: Sequence[float] | None,
                       alpha: float, steps: int, guidance: float, progress: bool = False, foot_lock: float = 0.0,
                       env_guidance: float = 1.0, anchor: str = "adapters",
                       env_guidance_fallback: float | None = None,
                       anchor_alpha: float = 0.0, anchor_t_max: int | None = None,
                       ballistic: float = 0.0, edit_t: int | None = None,
                       eta: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Generate every batch; returns joints (N, length, 22, 3) float32 (metres, Y-up, 20 fps) and (N,) bool: the
    samples re-sampled at ``env_guidance_fallback`` (the generator's ``Generation.fell_back``; all False without one).

    ``env`` is φ = (g_z, w_x, w_y) for a continuous SimDiff model, None for a backbone (``env_guidance`` then
    and ``anchor`` must stay at their defaults). ``ballistic``: the generator's ballistic flight strength (0: off);
    ``edit_t``: the edit anchor's last timestep at Earth (None: its default); ``eta``: the DDIM sampler's η (0:
    deterministic).
    """
    from tqdm import tqdm

    from simdiff.model.generator import guidance_kwargs
    from simdiff.motion.features import features_to_joints

    kwargs: dict[str, Any] = {"env": list(env), "alpha": alpha} if env is not None else {}
    kwargs.update(guidance_kwargs(env_guidance, anchor, anchor_alpha, anchor_t_max, env_guidance_fallback, ballistic,
                                  edit_t))
    if eta:
        kwargs["eta"] = eta
    out, flags = [], []
    for b in tqdm(batches, desc="prompts", disable=not progress, dynamic_ncols=True, leave=False):
        gen = generator.generate([b.prompt] * b.count, length, sampler="ddim", steps=steps, guidance=guidance,
                                 seed=b.noise_seed, foot_lock=foot_lock, **kwargs)
        out.append(np.asarray(features_to_joints(gen.features.detach().cpu().double()), dtype=np.float32))
        fell = getattr(gen, "fell_back", None)
        flags.append(np.zeros(b.count, dtype=bool) if fell is None else fell.detach().cpu().numpy().astype(bool))
    return np.concatenate(out), np.concatenate(flags)
