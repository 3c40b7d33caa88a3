"""Nested dataclass configs for the diffusion network (backbone + SimDiff parts).

Configs are plain values so that they serialise to ``config.json`` with
:func:`dataclasses.asdict` and come back with :func:`config_from_dict`.
"""

from __future__ import annotations

import dataclasses
import math
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


def config_from_dict(data: Any, cls: type[T], where: str | None = None, _prefix: str = "") -> T:
    """Build dataclass ``cls`` from a nested dict, recursing into dataclass-typed fields.

    Unknown keys raise :class:`SimdiffError` so that a typo in a config file is not silent. With ``where`` (the file
    name shown in messages), every value of a plain type (int, float, bool, str, a tuple of numbers, or a nested
    config) must have that type too: messages then read ``where: key.path = value …``, one line.
    """
    if not dataclasses.is_dataclass(cls):
        raise TypeError(f"{cls} is not a dataclass")
    if not isinstance(data, dict):
        what = f"{where}: {_prefix.rstrip('.')}" if _prefix else f"{where or cls.__name__}:"
        raise SimdiffError(f"{what} must be a JSON object {{...}}, got {json_kind(data)}")
    hints = typing.get_type_hints(cls)
    names = {f.name for f in dataclasses.fields(cls)}
    unknown = sorted(set(data) - names)
    if unknown:
        if where is not None:
            raise SimdiffError(f"{where}: unknown key {_prefix}{unknown[0]}"
                               + (f" (and {len(unknown) - 1} more)" if len(unknown) > 1 else "")
                               + f"; known keys here: {', '.join(sorted(names))}")
        raise SimdiffError(f"unknown {cls.__name__} keys: {', '.join(unknown)}")
    kwargs: dict[str, Any] = {}
    for name, value in data.items():
        sub = _dataclass_in(hints[name])
        if sub is not None and isinstance(value, dict):
            kwargs[name] = config_from_dict(value, sub, where, f"{_prefix}{name}.")
        else:
            kwargs[name] = value if where is None else _checked(hints[name], value, f"{where}: {_prefix}{name}")
    return cls(**kwargs)  # type: ignore[return-value]


def json_kind(value: Any) -> str:
    """How JSON spells the kind of ``value`` (for messages)."""
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "a boolean"
    if isinstance(value, (int, float)):
        return "a number"
    if isinstance(value, str):
        return "a string"
    if isinstance(value, list):
        return "an array"
    return "an object" if isinstance(value, dict) else "a value"


def _checked(annotation: Any, value: Any, label: str) -> Any:
    """``value`` if it fits ``annotation`` (an int also fits float; a list of numbers fits a tuple), else a one-line
    :class:`SimdiffError` ``label = value …``. Annotations other than plain types are not checked."""
    args = typing.get_args(annotation)
    if type(None) in args:
        if value is None:
            return None
        rest = [a for a in args if a is not type(None)]
        annotation = rest[0] if len(rest) == 1 else Any
    elif value is None and (annotation in (int, float, bool, str) or typing.get_origin(annotation) is tuple
                            or dataclasses.is_dataclass(annotation)):
        expected = "a JSON object {...}" if dataclasses.is_dataclass(annotation) else _expected(annotation)
        raise SimdiffError(f"{label} = null; expected {expected}")
    shown = json_value(value)
    if dataclasses.is_dataclass(annotation):
        raise SimdiffError(f"{label} = {shown}; expected a JSON object {{...}}")
    if annotation is bool and not isinstance(value, bool):
        raise SimdiffError(f"{label} = {shown}; expected true or false")
    if annotation is int and (isinstance(value, bool) or not isinstance(value, int)):
        raise SimdiffError(f"{label} = {shown}; expected a whole number")
    if annotation is float:
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise SimdiffError(f"{label} = {shown}; expected a finite number")
        return float(value)
    if annotation is str and not isinstance(value, str):
        raise SimdiffError(f"{label} = {shown}; expected a string")
    if typing.get_origin(annotation) is tuple:
        items = typing.get_args(annotation)
        numbers = all(a in (int, float) for a in items)
        if (not isinstance(value, (list, tuple)) or (items and Ellipsis not in items and len(value) != len(items))
                or (numbers and not all(isinstance(v, (int, float)) and not isinstance(v, bool)
                                        and math.isfinite(v) for v in value))):
            raise SimdiffError(f"{label} = {shown}; expected {_expected(annotation)}")
        return tuple(value)
    return value


def _expected(annotation: Any) -> str:
    if typing.get_origin(annotation) is tuple:
        items = [a for a in typing.get_args(annotation) if a is not Ellipsis]
        return f"an array of {len(items)} numbers" if items else "an array"
    return {int: "a whole number", float: "a finite number", bool: "true or false", str: "a string"}.get(
        annotation, "a value")


def json_value(value: Any, limit: int = 60) -> str:
    """``value`` as JSON, shortened to ``limit`` characters (for one-line messages)."""
    import json

    try:
        text = json.dumps(value)
    except (TypeError, ValueError):
        text = repr(value)
    return text if len(text) <= limit else text[: limit - 1] + "…"


def _dataclass_in(annotation: Any) -> type | None:
    """The dataclass type in ``annotation`` (``X`` or ``X | None``), else None."""
    if dataclasses.is_dataclass(annotation):
        return annotation
    for arg in typing.get_args(annotation):
        if dataclasses.is_dataclass(arg):
            return arg
    return None


MIN_MAX_LEN: int = 1000
"""Fewest rows of the positional table: it is indexed by the diffusion timestep (< 1000) and by the frame (≤ 196)."""
ACTIVATIONS: tuple[str, ...] = ("gelu", "relu")
SIM_MODES: tuple[str, ...] = ("continuous", "categorical")


def check_model_config(config: ModelConfig, where: str = "config.json", prefix: str = "") -> ModelConfig:
    """Refuse a model config whose network cannot be built or would be unbounded work; returns ``config``.

    Every message is one line ``where: key = value …`` (e.g. ``config.json: backbone.num_heads = 3 does not divide
    latent_dim 256``).
    """
    if not isinstance(config.backbone, BackboneConfig):
        raise SimdiffError(f"{where}: {prefix}backbone = {json_value(config.backbone)}; expected a JSON object {{...}}")
    b = config.backbone

    def bad(key: str, value: Any, why: str) -> SimdiffError:
        return SimdiffError(f"{where}: {prefix}{key} = {json_value(value)} {why}")

    def whole(key: str, value: Any, lo: int, hi: int) -> None:
        if isinstance(value, bool) or not isinstance(value, int):
            raise bad(key, value, "is not a whole number")
        if not lo <= value <= hi:
            raise bad(key, value, f"is outside {lo}..{hi}")

    def number(key: str, value: Any) -> float:
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise bad(key, value, "is not a finite number")
        return float(value)

    if b.nfeats != NFEATS or isinstance(b.nfeats, bool):
        raise bad("backbone.nfeats", b.nfeats, f"must be {NFEATS} (HumanML3D features per frame)")
    whole("backbone.latent_dim", b.latent_dim, 8, 4096)
    if b.latent_dim % 2:
        raise bad("backbone.latent_dim", b.latent_dim, "must be even (sinusoidal positions)")
    whole("backbone.num_layers", b.num_layers, 1, 64)
    whole("backbone.num_heads", b.num_heads, 1, b.latent_dim)
    if b.latent_dim % b.num_heads:
        raise bad("backbone.num_heads", b.num_heads, f"does not divide latent_dim {b.latent_dim}")
    whole("backbone.ff_size", b.ff_size, 8, 16384)
    whole("backbone.text_dim", b.text_dim, 1, 4096)
    whole("backbone.max_len", b.max_len, MIN_MAX_LEN, 100_000)
    if not 0.0 <= number("backbone.dropout", b.dropout) < 1.0:
        raise bad("backbone.dropout", b.dropout, "is outside [0, 1)")
    if b.activation not in ACTIVATIONS:
        raise bad("backbone.activation", b.activation, f"is not one of {', '.join(ACTIVATIONS)}")
    if not isinstance(b.mask_frames, bool):
        raise bad("backbone.mask_frames", b.mask_frames, "is not true or false")
    if not isinstance(config.text_encoder, str) or not config.text_encoder:
        raise bad("text_encoder", config.text_encoder, "is not an encoder name")
    sim = config.sim
    if sim is None:
        return config
    if not isinstance(sim, SimConfig):
        raise bad("sim", sim, "is not a JSON object {...} or null")
    if sim.mode not in SIM_MODES:
        raise bad("sim.mode", sim.mode, f"is not one of {', '.join(SIM_MODES)}")
    whole("sim.num_categories", sim.num_categories, 1, 1024)
    whole("sim.hidden", sim.hidden, 1, 4096)
    whole("sim.bottleneck", sim.bottleneck, 0, 4096)
    for key in ("gravity_scale", "wind_scale"):
        if number(f"sim.{key}", getattr(sim, key)) <= 0:
            raise bad(f"sim.{key}", getattr(sim, key), "must be > 0")
    number("sim.gravity_offset", sim.gravity_offset)
    return config
