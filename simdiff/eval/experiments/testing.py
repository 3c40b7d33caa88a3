"""Tiny stand-ins for tests and smoke runs of the experiments (not for results).

:func:`write_tiny_setup` writes a tiny synthetic corpus, tiny random models for every role
and a tiny evaluator; :class:`EchoProjector` replaces the simulator (the rollout is the motion
itself, so PhysDiff and re-tracking run in milliseconds).
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import torch

from simdiff.sim.env import Environment


class EchoProjector:
    """A fake simulator: returns each motion unchanged.

    Args:
        fail_every: every k-th motion of a call (k ≥ 1) is reported as a fall (0: never), after a second
            try (``attempts`` 2) whose rollout was not kept.
    Attributes:
        calls: one ``(frames per motion, φ per motion)`` entry per call.
    """

    def __init__(self, fail_every: int = 0) -> None:
        self.fail_every = fail_every
        self.calls: list[tuple[list[int], list[tuple[float, float, float]]]] = []

    def __call__(self, motions: Sequence[np.ndarray], envs: Sequence[Environment]) -> Iterator[tuple[np.ndarray, dict[str, Any]]]:
        self.calls.append(([len(m) for m in motions], [e.as_tuple() for e in envs]))
        for i, m in enumerate(motions):
            ok = not (self.fail_every and i % self.fail_every == 0)
            yield np.asarray(m, dtype=np.float32), {"success": ok, "status": "ok" if ok else "fell", "d_l2": float(i),
                                                    "err_mm": 10.0 * i, "attempts": 1 if ok else 2, "fallback": False}


def write_tiny_setup(root: str | Path, n_test: int = 16, frames: int = 44, seed: int = 0) -> dict[str, Path]:
    """Write ``corpus``, ``backbone``, ``adapters`` (continuous), ``adapters_binary`` (categorical, 2 classes)
    and ``evaluator`` under ``root``; returns their paths by role. Random weights; the adapters' output
    layers are random too (not zero as in training), so α and φ visibly change the motion."""
    from simdiff.eval.evaluator import EvaluatorConfig, TextMotionEvaluator, save_evaluator
    from simdiff.eval.testing import write_tiny_corpus
    from simdiff.model import ModelConfig, SimConfig, backbone_preset, build_network
    from simdiff.inference.generator import MotionGenerator

    root = Path(root)
    corpus = write_tiny_corpus(root / "corpus", n_train=4, n_test=n_test, frames=frames, seed=seed)
    mean = torch.from_numpy(np.load(corpus / "Mean.npy"))
    std = torch.from_numpy(np.load(corpus / "Std.npy"))
    torch.manual_seed(seed)
    out = {"corpus": corpus}
    for role, sim in (("backbone", None), ("adapters", SimConfig()), ("adapters_binary", SimConfig(mode="categorical", num_categories=2))):
        cfg = ModelConfig(backbone=backbone_preset("tiny"), sim=sim)
        network = build_network(cfg)
        with torch.no_grad():  # wake the zero-initialised adapter outputs so α and φ change the motion
            for name, p in network.named_parameters():
                if name.startswith("adapters.") and ".up." in name:
                    p.normal_(0.0, 0.5)
        MotionGenerator(network, cfg, None, mean, std).save(root / role)
        out[role] = root / role
    ev = TextMotionEvaluator(EvaluatorConfig(movement_dim=16, motion_hidden=16, text_hidden=16, embed_dim=8), mean, std)
    save_evaluator(root / "evaluator", ev)
    out["evaluator"] = root / "evaluator"
    return out
