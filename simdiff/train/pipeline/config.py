"""Pipeline settings as nested dataclasses, and the ``quick`` / ``cpu`` / ``gpu`` budgets."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Any

from simdiff.data.augment.filter import FilterConfig
from simdiff.errors import SimdiffError
from simdiff.train.geometric import CropConfig, GeometricLossConfig


@dataclass
class CorpusStage:
    """Where the motion corpus comes from.

    Attributes:
        path: an existing HumanML3D-layout corpus folder, or a pack folder (``simdiff train pack``).
        shared: else: build one from this shared data root (``simdiff.data.corpus.build``).
        licence, captions, mirror, workers: corpus build settings (``workers`` does not change it).
    """

    path: str = ""
    shared: str = ""
    licence: str = "all"
    captions: int = 3
    mirror: bool = True
    workers: int = 2


@dataclass
class AugmentStage:
    """Simulator augmentation (``simdiff.data.augment``); ``path``: use an existing augmented corpus/pack.

    ``filter``: the keep thresholds (``max_pose_d_l2`` is in normalised feature units, so it depends
    on the corpus's Std).
    """

    path: str = ""
    mode: str = "paired"
    conditions: int | None = None
    limit: int | None = None
    shard_size: int = 4
    residual_bound: float = 0.5
    workers: int = 0
    filter: FilterConfig = field(default_factory=FilterConfig)


@dataclass
class BackboneStage:
    """Backbone training (``simdiff.train.Trainer``, mode backbone).

    ``max_minutes`` (0 = none) stops early at a checkpoint when the wall-clock budget is spent;
    the stage is then done at the step it reached (recorded in its marker).
    """

    size: str = "small"
    mask_frames: bool = False
    steps: int = 2000
    batch_size: int = 32
    lr: float = 1e-4
    ema: bool = True
    ema_decay: float = 0.999
    save_every: int = 500
    max_minutes: float = 0.0
    losses: GeometricLossConfig = field(default_factory=GeometricLossConfig)
    crop: CropConfig = field(default_factory=CropConfig)


@dataclass
class AdapterStage:
    """Sim Encoder + Motion Adapters on the frozen backbone (eq. 10)."""

    sim_mode: str = "continuous"
    steps: int = 500
    batch_size: int = 32
    lr: float = 1e-4
    ema: bool = True
    ema_decay: float = 0.999
    save_every: int = 250
    max_minutes: float = 0.0
    env_pairs: float = 0.0
    """Weight of the paired φ-difference loss (``TrainConfig.env_pairs``; needs a paired augmentation)."""
    env_pairs_drift: float = 0.0
    """Weight of the twins' mean root-velocity term (``TrainConfig.env_pairs_drift``; with ``env_pairs``)."""


@dataclass
class EvaluatorStage:
    """Our text–motion evaluator (``simdiff.eval.train_evaluator``)."""

    epochs: int = 30
    batch_size: int = 32
    lr: float = 1e-3


@dataclass
class EvaluationStage:
    """A small run of the HumanML3D protocol on the test split (Earth φ unless ``env`` says otherwise)."""

    replications: int = 3
    batch_size: int = 32
    samples_limit: int = 256
    sampler: str = "ddim"
    steps: int = 50
    guidance: float = 2.5
    env: tuple[float, float, float] = (-9.81, 0.0, 0.0)


@dataclass
class ExportStage:
    """The exported model folder; ``shard_mib`` > 0 also writes ≤ that many MiB per weight shard."""

    shard_mib: float = 16.0
    alpha: float = 1.0


@dataclass
class PipelineConfig:
    """One pipeline run (saved as ``<out>/pipeline_config.json``)."""

    budget: str = "cpu"
    seed: int = 10
    text_encoder: str = "minilm"
    text_table: str = ""  # precomputed caption embeddings (simdiff.text.table) used instead of loading the encoder
    corpus: CorpusStage = field(default_factory=CorpusStage)
    augment: AugmentStage = field(default_factory=AugmentStage)
    backbone: BackboneStage = field(default_factory=BackboneStage)
    adapters: AdapterStage = field(default_factory=AdapterStage)
    evaluator: EvaluatorStage = field(default_factory=EvaluatorStage)
    evaluation: EvaluationStage = field(default_factory=EvaluationStage)
    export: ExportStage = field(default_factory=ExportStage)


def _quick() -> PipelineConfig:
    geo = GeometricLossConfig(position=0.0, velocity=0.05, foot_contact=0.05)
    return PipelineConfig(
        budget="quick",
        augment=AugmentStage(mode="paired", conditions=1, limit=4, shard_size=2, workers=1),
        backbone=BackboneStage(size="tiny", steps=6, batch_size=4, lr=1e-3, save_every=3, losses=geo,
                               crop=CropConfig(max_frames=32, trim_padding=True)),
        adapters=AdapterStage(steps=4, batch_size=4, lr=1e-3, save_every=2),
        evaluator=EvaluatorStage(epochs=1, batch_size=4),
        evaluation=EvaluationStage(replications=1, batch_size=4, samples_limit=4, steps=4),
        export=ExportStage(shard_mib=0.25),
    )


def _cpu() -> PipelineConfig:
    # The backbone is the design small_geo_crop, ahead of the 10 fps design at 40 training CPU-minutes each on
    # the all-source corpus.
    geo = GeometricLossConfig(position=0.0, velocity=1.0, foot_contact=1.0)
    return PipelineConfig(
        budget="cpu",
        augment=AugmentStage(mode="paired", workers=0),
        backbone=BackboneStage(size="small", steps=20000, batch_size=64, lr=2e-4, save_every=500, losses=geo,
                               crop=CropConfig(max_frames=120, trim_padding=True)),
        adapters=AdapterStage(steps=4000, batch_size=64, lr=2e-4, save_every=500),
        evaluator=EvaluatorStage(epochs=30, batch_size=32),
        evaluation=EvaluationStage(replications=3, samples_limit=256, steps=50),
    )


def _gpu() -> PipelineConfig:
    # One H200, <= 25 min wall: step counts are first guesses (not measured); max_minutes caps the
    # training stages so the budget holds whatever the real step rate turns out to be.
    geo = GeometricLossConfig(position=0.0, velocity=1.0, foot_contact=1.0)
    return PipelineConfig(
        budget="gpu",
        augment=AugmentStage(mode="paired", workers=16),
        backbone=BackboneStage(size="mdm", steps=30000, batch_size=128, lr=1e-4, save_every=1000, max_minutes=14.0,
                               losses=geo, crop=CropConfig(max_frames=196, trim_padding=True)),
        adapters=AdapterStage(steps=6000, batch_size=128, lr=1e-4, save_every=1000, max_minutes=4.0),
        evaluator=EvaluatorStage(epochs=20, batch_size=64),
        evaluation=EvaluationStage(replications=1, samples_limit=256, steps=50),
    )


BUDGETS: dict[str, Any] = {"quick": _quick, "cpu": _cpu, "gpu": _gpu}
"""Named presets: ``quick`` (tests: seconds), ``cpu`` (hours on a few cores), ``gpu`` (one H200, ≤ 25 min)."""


def budget_config(name: str) -> PipelineConfig:
    """The preset ``name``."""
    if name not in BUDGETS:
        raise SimdiffError(f"unknown budget {name!r}; choose one of {', '.join(BUDGETS)}")
    return BUDGETS[name]()


def set_option(config: PipelineConfig, assignment: str) -> None:
    """Apply ``section.key=value`` (value parsed as JSON when it parses, else a string) in place."""
    import json

    if "=" not in assignment:
        raise SimdiffError(f"--set {assignment!r}: expected section.key=value")
    dotted, raw = assignment.split("=", 1)
    try:
        value = json.loads(raw)
    except json.JSONDecodeError:
        value = raw
    target: Any = config
    parts = dotted.split(".")
    chain: list[Any] = [config]
    for part in parts[:-1]:
        if not dataclasses.is_dataclass(target) or not hasattr(target, part):
            raise SimdiffError(f"--set {assignment!r}: no section {part!r}")
        target = getattr(target, part)
        chain.append(target)
    if not dataclasses.is_dataclass(target) or parts[-1] not in {f.name for f in dataclasses.fields(target)}:
        raise SimdiffError(f"--set {assignment!r}: unknown setting {dotted!r}")
    old = getattr(target, parts[-1])
    if isinstance(old, tuple) and isinstance(value, list):
        value = tuple(value)
    if isinstance(old, float) and isinstance(value, int) and not isinstance(value, bool):
        value = float(value)
    if old is not None and value is not None and not isinstance(value, type(old)):
        raise SimdiffError(f"--set {assignment!r}: {dotted} must be {type(old).__name__}, got {value!r}")
    # frozen sections (FilterConfig) are replaced, and the replacement is set on their parent
    for depth in range(len(parts) - 1, -1, -1):
        holder = chain[depth]
        if not getattr(holder, "__dataclass_params__").frozen:
            setattr(holder, parts[depth], value)
            return
        value = dataclasses.replace(holder, **{parts[depth]: value})
    raise SimdiffError(f"--set {assignment!r}: the config is frozen")
