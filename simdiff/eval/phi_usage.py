"""Does a trained SimDiff network use φ? Denoising losses on twin batches of a simulator-augmented corpus.

Twin batches (:class:`simdiff.train.data.StepBatches` with ``pairs=True``) hold B/2 clips and the same
source clips simulated under another φ (the Earth one when kept), with one caption, window, t and ε
per pair. On them, with the network in eval mode and every t drawn from ``[t_min, t_max)``:

* ``loss_true``: x₀ MSE with each clip's own φ; ``loss_shuffled``: with φ permuted within the batch;
  ``loss_earth``: with Earth φ for every clip; ``loss_backbone``: without adapters (the frozen backbone).
  ``loss_shuffled − loss_true`` > 0 only when the network reads φ (paired differences, standard error).
* ``response_r2`` = 1 − MSE(x̂₀(φ) − x̂₀(φ'), x₀(φ) − x₀(φ')) / mean((x₀(φ) − x₀(φ'))²) over twins: the share of
  the simulator's φ-to-φ' change the network predicts (0: none, 1: all; negative: worse than predicting none).
  Twins' x_t differ too (by √ᾱ_t times that change), so part of it is read off x_t at low noise:
  ``response_r2_backbone`` (no adapters) and ``response_r2_shuffled`` (wrong φ) are that floor, and the gain
  of ``response_r2`` over them is what φ adds.

Units: normalised HumanML3D features (263); losses as in training (:func:`simdiff.diffusion.losses.masked_mse`).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import torch
from torch import nn

from simdiff.diffusion.ddpm import DDPMScheduler
from simdiff.diffusion.losses import masked_mse, twin_difference_mse
from simdiff.errors import SimdiffError
from simdiff.model.condition import Condition
from simdiff.train.data import StepBatcher, StepBatches
from simdiff.train.geometric import CropConfig

EARTH_ENV = (-9.81, 0.0, 0.0)


def phi_usage(network: nn.Module, dataset: Any, text_encoder: Any, *, batches: int = 20, batch_size: int = 64,
              seed: int = 12345, t_min: int = 0, t_max: int = 1000, max_frames: int = 120,
              device: torch.device | str = "cpu") -> dict[str, Any]:
    """Score ``network`` (a SimDiffNet with continuous φ) on ``batches`` seeded twin batches of ``dataset``.

    Returns ``loss_true``, ``loss_shuffled``, ``loss_earth``, ``loss_backbone`` (means), ``shuffled_minus_true``
    and ``response_r2`` as ``[mean, standard error over batches]``, and ``pairs`` (twins scored).
    """
    if batches < 2:
        raise SimdiffError(f"phi_usage needs at least 2 batches (for a standard error), got {batches}")
    if not 0 <= t_min < t_max <= 1000:
        raise SimdiffError(f"need 0 <= t_min < t_max <= 1000, got t_min {t_min}, t_max {t_max}")
    device = torch.device(device)
    network.eval()
    source = StepBatches(dataset, StepBatcher(len(dataset), batch_size, seed), seed, 0,
                         CropConfig(max_frames=max_frames, trim_padding=True), pairs=True)
    scheduler = DDPMScheduler()
    rows: dict[str, list[float]] = {k: [] for k in ("true", "shuffled", "earth", "backbone", "gain",
                                                    "r2_true", "r2_shuffled", "r2_backbone")}
    pairs = 0
    with torch.no_grad():
        for k in range(batches):
            b = source.batch(k)
            gen = torch.Generator().manual_seed(seed * 7919 + k)
            x0, mask, env = b["motion"].to(device), b["mask"].to(device), b["env"].to(device)
            h = x0.shape[0] // 2
            t = torch.randint(t_min, t_max, (h,), generator=gen).repeat(2).to(device)
            noise = torch.randn((h, *x0.shape[1:]), generator=gen).repeat(2, 1, 1).to(device)
            x_t = scheduler.add_noise(x0, noise, t)
            text = text_encoder.encode(b["captions"]).to(device)
            perm = torch.randperm(x0.shape[0], generator=gen).to(device)
            earth = torch.tensor([EARTH_ENV], device=device).repeat(x0.shape[0], 1)
            preds = {}
            for name, e in (("true", env), ("shuffled", env[perm]), ("earth", earth), ("backbone", None)):
                cond = Condition(text=text, uncond=torch.zeros(x0.shape[0], dtype=torch.bool, device=device),
                                 frame_mask=mask, env=e, alpha=1.0)
                preds[name] = network(x_t, t, cond)
                rows[name].append(float(masked_mse(preds[name], x0, mask)))
            rows["gain"].append(rows["shuffled"][-1] - rows["true"][-1])
            paired = b["paired"].to(device)
            null = float(twin_difference_mse(torch.zeros_like(x0), x0, mask, paired))
            if null > 0:
                for name in ("true", "shuffled", "backbone"):
                    rows[f"r2_{name}"].append(1.0 - float(twin_difference_mse(preds[name], x0, mask, paired)) / null)
            pairs += int(paired.sum())
    if not rows["r2_true"]:
        raise SimdiffError("no twin pairs with a difference in these batches: is this a paired augmentation?")

    def mean_se(v: list[float]) -> list[float]:
        a = np.asarray(v, dtype=np.float64)
        return [float(a.mean()), float(a.std(ddof=1) / np.sqrt(len(a))) if len(a) > 1 else float("nan")]

    return {"loss_true": float(np.mean(rows["true"])), "loss_shuffled": float(np.mean(rows["shuffled"])),
            "loss_earth": float(np.mean(rows["earth"])), "loss_backbone": float(np.mean(rows["backbone"])),
            "shuffled_minus_true": mean_se(rows["gain"]), "response_r2": mean_se(rows["r2_true"]),
            "response_r2_shuffled": mean_se(rows["r2_shuffled"]), "response_r2_backbone": mean_se(rows["r2_backbone"]),
            "pairs": pairs,
            "batches": batches, "batch_size": batch_size, "seed": seed, "t_min": t_min, "t_max": t_max}
