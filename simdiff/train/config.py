"""Training configs (nested dataclasses; saved as ``train_config.json`` in the run folder)."""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from pathlib import Path

from simdiff.errors import SimdiffError
from simdiff.model.config import ModelConfig
from simdiff.train.geometric import CropConfig, GeometricLossConfig


@dataclass
class OptimConfig:
    """AdamW settings (MDM: lr 1e-4, no weight decay, no clipping, constant lr).

    ``lr_schedule``: ``"constant"`` (MDM) or ``"cosine"`` (lr · ½(1 + cos(π · step / steps)): from ``lr`` at step 0
    to 0 at the run's last step; a function of the step alone, so a resumed run continues the same curve).
    """

    lr: float = 1e-4
    weight_decay: float = 0.0
    betas: tuple[float, float] = (0.9, 0.999)
    grad_clip: float = 0.0
    lr_schedule: str = "constant"


LR_SCHEDULES: tuple[str, ...] = ("constant", "cosine")
"""Names :attr:`OptimConfig.lr_schedule` accepts."""
DRIFT_PAIRS: tuple[str, ...] = ("all", "wind")
"""Which twins the paired loss and the drift term compare (``TrainConfig.pair_twins``, ``TrainConfig.drift_pairs``)."""


def lr_at(optim: OptimConfig, step: int, steps: int) -> float:
    """Learning rate of optimiser step ``step`` (0-based) in a run of ``steps`` steps."""
    if optim.lr_schedule == "constant":
        return optim.lr
    if optim.lr_schedule == "cosine":
        return optim.lr * 0.5 * (1.0 + math.cos(math.pi * min(step, steps) / max(steps, 1)))
    raise SimdiffError(f"unknown lr_schedule {optim.lr_schedule!r} (choose from {', '.join(LR_SCHEDULES)})")


@dataclass
class TrainConfig:
    """One training run.

    Attributes:
        mode: ``"backbone"`` (train everything) or ``"adapters"`` (frozen backbone; Sim Encoder + adapters).
        steps: optimiser steps in total (a resumed run continues up to this).
        batch_size: global batch (split evenly across DDP processes).
        seed: seeds data order, caption/crop choices, t, ε, text dropout and dropout, per step.
        cond_mask_prob: probability of dropping the text of a sample (CFG training; 0.1).
        ema: keep an exponential moving average of the trained weights (exported if on).
        ema_decay: EMA β.
        save_every: checkpoint period in steps (0: only at the end).
        keep_checkpoints: how many step folders to keep.
        log_every: loss averaging window for the progress bar.
        losses: MDM's geometric loss weights (all 0 by default: plain x₀ MSE).
        crop: length-cropped batches (off by default).
        env_pairs: weight λ of the paired φ-difference loss (adapters mode; 0 = off, the paper's plain loss).
            Each batch is B/2 clips and their twins (the same source clip simulated under another φ, the Earth
            one when kept), both with the same caption, window, t, ε and text dropout, and the loss adds
            ``λ · MSE(x̂₀(φ) − x̂₀(φ'), x₀(φ) − x₀(φ'))``: the response to φ, which the plain loss sees only as a
            small part of each sample's error. The frozen backbone then runs without dropout so twin
            predictions differ only through φ.
        env_pairs_drift: weight μ of the twins' mean root-velocity term (needs ``env_pairs`` > 0; 0 = off):
            ``μ · (mean_t Δx̂₀_root − mean_t Δx₀_root)²`` (:func:`simdiff.diffusion.losses.twin_drift_mse`), the
            steady drift a wind gives a walker, which the per-frame pair loss weighs as a tiny part of its error.
        targets: adapters mode: ``"simulated"`` (the simulator's replays), ``"source-anchored"`` (the source clip
            plus the replay's change against its Earth twin) or ``"source-anchored-pairs"`` (the same, but an Earth
            item without twins keeps its replay); :mod:`simdiff.data.augment.anchored`.
        drift_pairs: which twins the drift term (``env_pairs_drift``) compares: ``"all"`` or ``"wind"`` (only twins
            whose φ differ in wind). Paired over their common frames (``twin_frames="prefix"``), low-gravity twins
            differ in mean root velocity 4–13× as much as wind twins (their longer flights lag behind), which
            swamps the wind's drift.
        pair_twins: which twins the per-frame paired loss (``env_pairs``) compares: ``"all"`` or ``"wind"`` (only
            twins whose φ differ in wind; gravity's answer is then learnt from the plain denoising loss alone). A
            longer low-gravity flight puts the twins out of step after its first landing; there the per-frame
            difference cannot be told from the noise, and regressing it averages timings away.
        twin_frames: adapters mode: ``"equal"`` (replays of one source clip are twins only with equal frames),
            ``"prefix"`` (trimmed to their common first frames, so replays that fly longer under low gravity are
            paired too) or ``"overlap"`` (kept whole, cropped from their first frames and compared over the frames
            they share, so a longer flight and its landing stay in the target);
            :class:`simdiff.data.augment.dataset.AugmentedHumanML3D`.
        cross_twins: share p in [0, 1] of paired twins (needs ``env_pairs`` > 0) whose x_t is built from the *other*
            twin's x₀ (same t and ε) while the target stays their own: "replay my twin's motion under my φ". The plain
            loss lets the network read a jump's height off x_t below t ≈ 900 whatever φ says (measured with a probe), so
            φ alone decides it in the noisiest steps; crossed twins ask φ to act where x_t already shows the motion
            (an edit of the twin, as the simulator's replay is; sample with the edit anchor,
            :mod:`simdiff.diffusion.guidance`). 0 = off. Measured: 600 CPU steps at p 0.5 taught the single
            denoising step half of the simulator's low-g lift.
        cross_match: a regular expression (case-insensitive, searched in the caption) limiting ``cross_twins`` to the
            twin pairs whose caption matches, e.g. ``"jump|hop|leap"``: only those pairs are crossed, the rest keep
            their own x_t. "" (default) = every paired twin may be crossed.
    """

    mode: str = "backbone"
    steps: int = 1000
    batch_size: int = 32
    seed: int = 10
    cond_mask_prob: float = 0.1
    ema: bool = False
    ema_decay: float = 0.9999
    save_every: int = 500
    keep_checkpoints: int = 2
    log_every: int = 10
    optim: OptimConfig = field(default_factory=OptimConfig)
    losses: GeometricLossConfig = field(default_factory=GeometricLossConfig)
    crop: CropConfig = field(default_factory=CropConfig)
    env_pairs: float = 0.0
    env_pairs_drift: float = 0.0
    targets: str = "simulated"
    twin_frames: str = "equal"
    drift_pairs: str = "all"
    pair_twins: str = "all"
    cross_twins: float = 0.0
    cross_match: str = ""


@dataclass
class RunConfig:
    """What a run folder's ``train_config.json`` holds."""

    model: ModelConfig = field(default_factory=ModelConfig)
    train: TrainConfig = field(default_factory=TrainConfig)


MAX_CROP_FRAMES: int = 196
"""Longest crop window (``train.crop.max_frames``): the dataset's padded length."""


def read_run_config(path: str | os.PathLike[str]) -> RunConfig:
    """Read and check a run config file (``train --config``, a run folder's ``train_config.json``).

    Raises:
        SimdiffError: unreadable or invalid JSON, not an object, an unknown key, a value of the wrong type or out of
            range; one line naming the file and the key.
    """
    from simdiff.fsio import read_config_json
    from simdiff.model.config import config_from_dict

    path = Path(path)
    if not path.is_file():
        raise SimdiffError(f"{path}: no such config file")
    data = read_config_json(path)
    config = config_from_dict(data, RunConfig, str(path))
    check_train_config(config.train, str(path))
    return config


def check_train_config(tc: TrainConfig, where: str = "train_config.json") -> TrainConfig:
    """Refuse training settings that a run would accept silently and then misuse; returns ``tc``.

    Messages are one line ``where: train.key = value …``.
    """
    from simdiff.model.config import json_value

    def bad(key: str, value: object, why: str) -> SimdiffError:
        return SimdiffError(f"{where}: train.{key} = {json_value(value)} {why}")

    def whole(key: str, lo: int, hi: int | None = None) -> None:
        value = _get(tc, key)
        if isinstance(value, bool) or not isinstance(value, int):
            raise bad(key, value, "is not a whole number")
        if value < lo or (hi is not None and value > hi):
            raise bad(key, value, f"is outside {lo}..{hi}" if hi is not None else f"must be ≥ {lo}")

    def number(key: str, lo: float, hi: float = math.inf, *, below: bool = False) -> None:
        value = _get(tc, key)
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise bad(key, value, "is not a finite number")
        if value < lo or value > hi or (below and value == hi):
            span = f"[{lo:g}, {hi:g}{')' if below else ']'}" if math.isfinite(hi) else f"≥ {lo:g}"
            raise bad(key, value, f"is outside {span}")

    whole("steps", 1)
    whole("batch_size", 1)
    whole("seed", 0, 2**32 - 1)
    whole("save_every", 0)
    whole("keep_checkpoints", 1)
    whole("log_every", 1)
    number("cond_mask_prob", 0.0, 1.0)
    if not isinstance(tc.ema, bool):
        raise bad("ema", tc.ema, "is not true or false")
    number("ema_decay", 0.0, 1.0)
    number("optim.lr", 0.0, 1.0)
    number("optim.weight_decay", 0.0)
    number("optim.grad_clip", 0.0)
    betas = tc.optim.betas
    if (not isinstance(betas, (list, tuple)) or len(betas) != 2
            or not all(isinstance(b, (int, float)) and not isinstance(b, bool) and 0 <= b < 1 for b in betas)):
        raise bad("optim.betas", betas, "must be two numbers in [0, 1)")
    if tc.optim.lr_schedule not in LR_SCHEDULES:
        raise bad("optim.lr_schedule", tc.optim.lr_schedule, f"is not one of {', '.join(LR_SCHEDULES)}")
    for key in ("position", "velocity", "foot_contact"):
        number(f"losses.{key}", 0.0)
    whole("crop.max_frames", 0, MAX_CROP_FRAMES)
    if not isinstance(tc.crop.trim_padding, bool):
        raise bad("crop.trim_padding", tc.crop.trim_padding, "is not true or false")
    number("env_pairs", 0.0)
    number("env_pairs_drift", 0.0)
    number("cross_twins", 0.0, 1.0)
    if not isinstance(tc.cross_match, str):
        raise bad("cross_match", tc.cross_match, "is not a string")
    return tc


def _get(obj: object, dotted: str) -> object:
    for part in dotted.split("."):
        obj = getattr(obj, part)
    return obj
