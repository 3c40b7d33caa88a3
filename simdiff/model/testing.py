"""Helpers for tests and demos: the smallest model configuration."""

from __future__ import annotations

from simdiff.model.config import ModelConfig, SimConfig, backbone_preset


def tiny_model_config(sim: bool = False, dropout: float = 0.1) -> ModelConfig:
    """The ``tiny`` backbone preset, with the default SimDiff adapters when ``sim``."""
    return ModelConfig(backbone=backbone_preset("tiny", dropout=dropout), sim=SimConfig() if sim else None)
