"""Helpers for tests and demos of the viewer: a tiny random SimDiff model folder."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import torch

STATS_DIR = Path(__file__).resolve().parent.parent / "assets" / "cmu_stats"


def write_tiny_model(folder: str | os.PathLike[str], seed: int = 0, jitter: float = 0.05) -> Path:
    """Write a random ``tiny`` continuous-φ SimDiff model (``model.safetensors`` + ``config.json``).

    Every weight gets Gaussian noise of std ``jitter`` so that the zero-initialised Motion Adapters
    react to gravity and wind; the normaliser is the shipped CMU feature mean/std. Its text encoder
    is MiniLM by name: pass a ``simdiff.train.testing.HashTextEncoder`` to the service to skip loading it.

    Returns:
        the folder.
    """
    from simdiff.model.checkpoint import build_network
    from simdiff.inference.generator import MotionGenerator
    from simdiff.model.testing import tiny_model_config

    config = tiny_model_config(sim=True)
    torch.manual_seed(seed)
    network = build_network(config)
    with torch.no_grad():
        for param in network.parameters():
            param.add_(jitter * torch.randn_like(param))
    mean = torch.from_numpy(np.load(STATS_DIR / "Mean.npy").astype(np.float32))
    std = torch.from_numpy(np.load(STATS_DIR / "Std.npy").astype(np.float32))
    folder = Path(folder)
    MotionGenerator(network, config, None, mean, std).save(folder)
    return folder
