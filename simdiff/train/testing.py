"""Small helpers for tests and smoke runs: a deterministic stand-in text encoder and tiny configs."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import torch

from simdiff.model.testing import tiny_model_config
from simdiff.train.config import OptimConfig, RunConfig, TrainConfig


class HashTextEncoder:
    """Deterministic pseudo-embeddings (unit-variance Gaussian per caption), independent of PYTHONHASHSEED.

    Stands in for a real encoder (MiniLM's 384-d by default) where text semantics do not matter;
    its ``name`` is ``hash``, so that nothing it produces (a caption cache) passes for MiniLM's.
    """

    name = "hash"

    def __init__(self, dim: int = 384) -> None:
        self.dim = dim

    def encode(self, texts: Sequence[str]) -> torch.Tensor:
        """(B,) captions → (B, dim) float32."""
        seeds = [sum((i + 1) * ord(c) for i, c in enumerate(t)) for t in texts]
        return torch.stack([torch.randn(self.dim, generator=torch.Generator().manual_seed(s)) for s in seeds])


class HashMiniLM(HashTextEncoder):
    """:class:`HashTextEncoder` under MiniLM's name: stands in for the real encoder where a table of its
    embeddings is written (``simdiff.text.table``) and read back as MiniLM's."""

    name = "minilm"


def tiny_run_config(steps: int = 10, mode: str = "backbone", sim: bool = False, dropout: float = 0.1,
                    lr: float = 1e-3, **train: Any) -> RunConfig:
    """A ``tiny``-preset run config (batch 4, no periodic checkpoints unless ``save_every`` is given)."""
    model = tiny_model_config(sim=sim, dropout=dropout)
    train.setdefault("batch_size", 4)
    train.setdefault("save_every", 0)
    return RunConfig(model=model, train=TrainConfig(mode=mode, steps=steps, optim=OptimConfig(lr=lr), **train))


class EchoProjector:
    """Stands in for the simulator in tests: the rollout is the reference itself and every pair
    passes the keep filter (small pose distance and residual)."""

    def __init__(self) -> None:
        self.pairs = 0

    def __call__(self, motions: Sequence[Any], envs: Sequence[Any]) -> Any:
        import numpy as np

        for m in motions:
            self.pairs += 1
            yield np.asarray(m, dtype=np.float32), {"success": True, "d_l2_pose": 0.5, "d_l2": 0.5,
                                                     "residual": {"force_mean_n": 1.0, "force_mean_mg": 0.01},
                                                     "cpu_s": 0.0}


def tiny_generator(sim: bool = True, active_adapters: bool = True):  # -> MotionGenerator (torch-heavy import)
    """A random ``tiny`` model with the hash text encoder; its adapters are zero-initialised, so
    ``active_adapters`` perturbs them to make φ matter. Feature std 0.05 keeps random outputs human-sized."""
    from simdiff.inference.generator import MotionGenerator
    from simdiff.model import build_network

    torch.manual_seed(0)
    config = tiny_model_config(sim=sim, dropout=0.1)
    network = build_network(config)
    if sim and active_adapters:
        with torch.no_grad():
            for name, p in network.named_parameters():
                if "adapter" in name and name.endswith("weight"):
                    p.add_(0.3 * torch.randn_like(p))
    return MotionGenerator(network, config, HashTextEncoder(), std=torch.full((263,), 0.05))
