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
    from simdiff.inference.generator import MotionGenerator
    from simdiff.model.checkpoint import build_network
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


class SlowGenerator:
    """Stands in for a ``MotionGenerator`` in server tests: ``config.steps`` sampler steps of ``step_s`` seconds
    each through the service's ``progress`` hook, then a motion of all-``value`` features (NaN: a broken sampler).

    Attributes:
        started, finished: generations begun and completed (a cancelled one is started, not finished).
    """

    is_simdiff = False

    def __init__(self, step_s: float = 0.05, value: float = 0.0) -> None:
        from types import SimpleNamespace

        self.config = SimpleNamespace(sim=None)  # a backbone-only model: no φ
        self.step_s = step_s
        self.value = value
        self.started = 0
        self.finished = 0

    def generate(self, texts, frames, config, *, env=None, seed=0, progress=None):
        import time
        from types import SimpleNamespace

        self.started += 1
        steps = range(config.steps)
        for _ in progress(steps) if progress is not None else steps:
            time.sleep(self.step_s)
        self.finished += 1
        features = torch.full((frames, 263), float(self.value))
        return SimpleNamespace(clips=lambda: [features])


def slow_service(folder: str | os.PathLike[str], generator: SlowGenerator | None = None, **kwargs: object) -> object:
    """A ``MotionService`` over ``folder`` (no model needed) whose generator is ``generator`` (a new
    :class:`SlowGenerator` by default); ``kwargs`` go to the service."""
    from simdiff.serve.service import MotionService

    service = MotionService(folder, **kwargs)
    service._generator = generator if generator is not None else SlowGenerator()
    return service
