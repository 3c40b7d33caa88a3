"""Nested dataclass configs for the diffusion network (backbone + SimDiff parts).

Configs are plain values so that they serialise to ``config.json`` with
:func:`dataclasses.asdict` and come back with :func:`config_from_dict`.
"""

from __future__ import annotations

import dataclasses
import typing
from dataclasses import dataclass, field
from typing import Any, TypeVar

from simdiff.errors import SimdiffError

NFEATS: int = 263
"""HumanML3D feature size per frame."""


@dataclass
class BackboneConfig:
    """MDM-style transformer-encoder denoiser.

    Attributes:
        nfeats: feature size per frame (263 for HumanML3D).
        latent_dim: model width d.
        num_layers: transformer encoder layers.
        num_heads: attention heads.
        ff_size: feed-forward hidden size.
        dropout: dropout in the PE and every layer.
        activation: ``"gelu"`` or ``"relu"``.
        text_dim: size of the text embedding fed to ``embed_text`` (512 CLIP, 384 MiniLM).
        max_len: rows of the sinusoidal table (MDM: 5000); bounds both t and frame count.
        mask_frames: pass a key-padding mask to attention (False reproduces MDM).
    """

    nfeats: int = NFEATS
    latent_dim: int = 256
    num_layers: int = 4
    num_heads: int = 4
    ff_size: int = 512
    dropout: float = 0.1
    activation: str = "gelu"
    text_dim: int = 384
    max_len: int = 5000
    mask_frames: bool = False


@dataclass
class SimConfig:
    """Sim Encoder and Motion Adapters (SimDiff).

    Attributes:
        mode: ``"continuous"`` (φ = (g_z, w_x, w_y) floats) or ``"categorical"`` (an index).
        num_categories: number of environment categories (categorical mode).
        hidden: Sim Encoder hidden width (paper: 64).
        bottleneck: adapter bottleneck; ``0`` means ``min(256, latent_dim // 2)``.
        gravity_scale: g_z is divided by this (m/s²) before the MLP.
        wind_scale: w_x, w_y are divided by this (N) before the MLP.
        gravity_offset: subtracted from g_z before scaling (Earth gravity maps to 0).
    """

    mode: str = "continuous"
    num_categories: int = 8
    hidden: int = 64
    bottleneck: int = 0
    gravity_scale: float = 9.81
    wind_scale: float = 10.0
    gravity_offset: float = -9.81


@dataclass
class ModelConfig:
    """A full model: backbone, optional SimDiff part, text encoder name."""

    backbone: BackboneConfig = field(default_factory=BackboneConfig)
    sim: SimConfig | None = None
    text_encoder: str = "minilm"


PRESETS: dict[str, dict[str, Any]] = {
    "mdm": dict(latent_dim=512, num_layers=8, num_heads=4, ff_size=1024, dropout=0.1, activation="gelu"),
    "small": dict(latent_dim=256, num_layers=4, num_heads=4, ff_size=512, dropout=0.1, activation="gelu"),
    "tiny": dict(latent_dim=64, num_layers=2, num_heads=4, ff_size=128, dropout=0.0, activation="gelu"),
}
"""Named backbone sizes: ``mdm`` is the paper's, ``small`` the CPU default, ``tiny`` for tests."""


def backbone_preset(name: str, **overrides: Any) -> BackboneConfig:
    """Return the :class:`BackboneConfig` for preset ``name`` with ``overrides`` applied."""
    if name not in PRESETS:
        raise SimdiffError(f"unknown model size {name!r}; choose one of {', '.join(PRESETS)}")
    return BackboneConfig(**{**PRESETS[name], **overrides})


T = TypeVar("T")


def config_from_dict(data: dict[str, Any], cls: type[T]) -> T:
    """Build dataclass ``cls`` from a nested dict, recursing into dataclass-typed fields.

    Unknown keys raise :class:`SimdiffError` so that a typo in a config file is not silent.
    """
    if not dataclasses.is_dataclass(cls):
        raise TypeError(f"{cls} is not a dataclass")
    hints = typing.get_type_hints(cls)
    names = {f.name for f in dataclasses.fields(cls)}
    unknown = set(data) - names
    if unknown:
        raise SimdiffError(f"unknown {cls.__name__} keys: {', '.join(sorted(unknown))}")
    kwargs: dict[str, Any] = {}
    for name, value in data.items():
        sub = _dataclass_in(hints[name])
        kwargs[name] = config_from_dict(value, sub) if sub is not None and isinstance(value, dict) else value
    return cls(**kwargs)  # type: ignore[return-value]


def _dataclass_in(annotation: Any) -> type | None:
    """The dataclass type in ``annotation`` (``X`` or ``X | None``), else None."""
    if dataclasses.is_dataclass(annotation):
        return annotation
    for arg in typing.get_args(annotation):
        if dataclasses.is_dataclass(arg):
            return arg
    return None
