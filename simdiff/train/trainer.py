"""The trainer: optimiser, EMA, deterministic batches, checkpoints, resume, DDP.

Backbone mode trains an ``MDMBackbone``; adapters mode loads a backbone checkpoint into a
``SimDiffNet``, freezes it, and trains only the Sim Encoder and the Motion Adapters.

Every random choice of step k (batch indices, caption/crop, t, ε, text dropout, dropout
masks) is seeded from ``(seed, k, rank)``, so a run stopped after any checkpoint and resumed
ends with bit-identical weights.
"""

from __future__ import annotations

import dataclasses
import json
import math
import re
import time
from pathlib import Path
from typing import Any, Callable, Iterator, Sequence

import numpy as np
import torch
from torch import Tensor, nn

from simdiff.diffusion.ddpm import DDPMScheduler
from simdiff.diffusion.losses import diffusion_prediction, masked_mse, twin_difference_mse, twin_drift_mse
from simdiff.errors import SimdiffError
from simdiff.model.checkpoint import build_network, load_pretrained, save_pretrained
from simdiff.model.condition import Condition
from simdiff.model.provenance import Provenance, write_provenance
from simdiff.model.simdiff_net import SimDiffNet
from simdiff.text.cache import CachedTextEncoder
from simdiff.train.config import DRIFT_PAIRS, RunConfig, lr_at
from simdiff.train.data import MotionDataset, StepBatcher, StepBatches
from simdiff.train.ema import EMA
from simdiff.train.geometric import geometric_loss
from simdiff.train.state import latest_checkpoint, read_checkpoint, write_checkpoint


TEXT_CACHE = "text_cache.safetensors"


def _same_weights_layout(a: Any, b: Any) -> bool:
    """Two backbone configs hold the same weights (``mask_frames`` only changes attention, not the weights)."""
    return dataclasses.replace(a, mask_frames=b.mask_frames) == b


def _seeds(*key: int) -> tuple[int, int]:
    """Two independent 63-bit seeds derived from ``key``."""
    a, b = np.random.SeedSequence([int(k) & 0xFFFFFFFF for k in key]).generate_state(2, dtype=np.uint64)
    return int(a) >> 1, int(b) >> 1


class Trainer:
    """Train a backbone or SimDiff adapters into ``run_dir``.

    Args:
        run_dir: the run folder (``checkpoints/``, ``model/``, ``train_config.json``).
        config: model + training config. For ``adapters``, ``config.model.sim`` must be set
            and the backbone part is taken from ``init_model``.
        dataset: items ``dict(motion (196, 263), length, caption[, env][, env_index])``.
        text_encoder: anything with ``name``, ``dim`` and ``encode(list[str]) -> (B, dim)``;
            default: the encoder named in the model config.
        device: where to train (passed explicitly; float32).
        init_model: a backbone model folder (``model.safetensors`` + ``config.json``; a SimDiff folder gives its
            backbone): adapters mode trains on it frozen; backbone mode starts from its weights (a warm start
            with a fresh optimiser; ignored when ``run_dir`` already holds a checkpoint to resume).
        init_adapters: adapters mode: a SimDiff model folder whose Sim Encoder and Motion Adapters the run starts
            from (same sim and backbone config) instead of zero-initialised ones; ignored when resuming.
        mean, std: (263,) normaliser saved with the model (default: ``dataset.normalizer`` or init model's).
        resume: continue from ``run_dir``'s latest checkpoint when there is one.
        rank, world_size: DDP process (``torch.distributed`` must already be initialised when > 1).
        provenance: what the run trains on (:mod:`simdiff.model.provenance`); written as
            ``model/provenance.json`` with every export when given.
        loader_workers: DataLoader processes that build batches ahead (0: in this process); the batches, and
            so the run, are the same either way.
    """

    def __init__(self, run_dir: str | Path, config: RunConfig, dataset: MotionDataset, *, text_encoder: Any = None,
                 device: torch.device | str = "cpu", init_model: str | Path | None = None,
                 init_adapters: str | Path | None = None,
                 mean: Tensor | None = None, std: Tensor | None = None, resume: bool = True,
                 rank: int = 0, world_size: int = 1, provenance: Provenance | None = None,
                 loader_workers: int = 0) -> None:
        self.run_dir = Path(run_dir)
        if loader_workers < 0:
            raise SimdiffError(f"loader_workers must be >= 0, got {loader_workers}")
        self.loader_workers = loader_workers
        self.provenance = provenance
        self.config = config
        self.dataset = dataset
        self.device = torch.device(device)
        self.rank, self.world_size = rank, world_size
        tc = config.train
        if tc.mode not in ("backbone", "adapters"):
            raise SimdiffError(f"training mode must be backbone or adapters, got {tc.mode!r}")
        if not (math.isfinite(tc.env_pairs) and tc.env_pairs >= 0):
            raise SimdiffError(f"env_pairs must be a finite weight >= 0, got {tc.env_pairs}")
        if not (math.isfinite(tc.env_pairs_drift) and tc.env_pairs_drift >= 0):
            raise SimdiffError(f"env_pairs_drift must be a finite weight >= 0, got {tc.env_pairs_drift}")
        if tc.env_pairs_drift > 0 and not tc.env_pairs > 0:
            raise SimdiffError(f"env_pairs_drift = {tc.env_pairs_drift} needs env_pairs > 0 (the drift term compares twins)")
        if tc.drift_pairs not in DRIFT_PAIRS:
            raise SimdiffError(f"drift_pairs must be 'all' or 'wind', got {tc.drift_pairs!r}")
        if tc.pair_twins not in DRIFT_PAIRS:
            raise SimdiffError(f"pair_twins must be 'all' or 'wind', got {tc.pair_twins!r}")
        if not (isinstance(tc.cross_twins, (int, float)) and 0.0 <= tc.cross_twins <= 1.0):
            raise SimdiffError(f"cross_twins must be a share in [0, 1], got {tc.cross_twins}")
        if tc.cross_twins > 0 and not tc.env_pairs > 0:
            raise SimdiffError(f"cross_twins = {tc.cross_twins} needs env_pairs > 0 (it crosses twins of paired batches)")
        if not isinstance(tc.cross_match, str):
            raise SimdiffError(f"cross_match must be a regular expression string, got {tc.cross_match!r}")
        try:
            self._cross_match = re.compile(tc.cross_match, re.IGNORECASE) if tc.cross_match else None
        except re.error as exc:
            raise SimdiffError(f"cross_match {tc.cross_match!r} is not a regular expression: {exc}") from None
        if self._cross_match is not None and not tc.cross_twins > 0:
            raise SimdiffError(f"cross_match {tc.cross_match!r} needs cross_twins > 0 (it limits which twins are crossed)")
        if tc.env_pairs > 0 and tc.mode != "adapters":
            raise SimdiffError(f"env_pairs = {tc.env_pairs} needs adapters mode (the φ-difference loss trains the adapters)")
        with torch.random.fork_rng(devices=[]):
            torch.manual_seed(tc.seed)  # the initial weights depend on the seed only
            self.network = build_network(config.model)
        init_mean, init_std = None, None
        existing = latest_checkpoint(self.run_dir)  # a run to resume: warm starts are ignored
        if tc.mode == "adapters":
            if config.model.sim is None or not isinstance(self.network, SimDiffNet):
                raise SimdiffError("adapter training needs a sim config (the SimDiff part)")
            if init_model is None and existing is None:
                raise SimdiffError("adapter training needs a backbone checkpoint (--init MODEL_DIR)")
            if init_model is not None:
                init_mean, init_std = self._load_backbone(Path(init_model))
            if init_adapters is not None and existing is None:
                self._load_adapters(Path(init_adapters))
            self.network.backbone.requires_grad_(False)
        elif config.model.sim is not None:
            raise SimdiffError("backbone training takes no sim config; train adapters afterwards")
        elif init_adapters is not None:
            raise SimdiffError("init_adapters needs adapters mode")
        elif init_model is not None and existing is None:
            init_mean, init_std = self._load_backbone(Path(init_model))
        self.mean, self.std = self._normalizer(mean, std, init_mean, init_std)
        self.network.to(self.device)
        self.trainable = {n: p for n, p in self.network.named_parameters() if p.requires_grad}
        o = tc.optim
        # lr_at refuses an unknown schedule here, before any step; each step then sets its own lr
        self.optimizer = torch.optim.AdamW(list(self.trainable.values()), lr=lr_at(o, 0, tc.steps),
                                           weight_decay=o.weight_decay, betas=tuple(o.betas))
        self.scheduler = DDPMScheduler()
        if text_encoder is None:
            from simdiff.text.base import load_text_encoder

            text_encoder = load_text_encoder(config.model.text_encoder, self.device)
        if text_encoder.dim != config.model.backbone.text_dim:
            raise SimdiffError(f"text encoder gives {text_encoder.dim}-d vectors, the model expects {config.model.backbone.text_dim}")
        self.text = text_encoder if isinstance(text_encoder, CachedTextEncoder) else CachedTextEncoder(text_encoder, self.device)
        if resume:  # embeddings as of the last checkpoint, so a resumed run sees bit-identical text vectors
            self.text.load(self.run_dir / TEXT_CACHE)
        self.batcher = StepBatcher(len(dataset), tc.batch_size, tc.seed, world_size, rank)
        self.step = 0
        ema_state = None
        checkpoint = existing if resume else None
        if checkpoint is not None:
            ema_state = self._restore(checkpoint)
        self.model: nn.Module = self.network
        if world_size > 1:
            from torch.nn.parallel import DistributedDataParallel

            self.model = DistributedDataParallel(self.network, device_ids=None if self.device.type == "cpu" else [self.device])
        self.ema = EMA(self.trainable, tc.ema_decay) if tc.ema else None
        if self.ema is not None and ema_state is not None:
            self.ema.load_state_dict(ema_state)
        self.history: list[float] = []
        self._saved_step = self.step if checkpoint is not None else -1

    # --- setup ----------------------------------------------------------------------------

    def _load_backbone(self, folder: Path) -> tuple[Tensor | None, Tensor | None]:
        network, init_config, extra = load_pretrained(folder, "cpu")
        backbone = network.backbone if isinstance(network, SimDiffNet) else network
        if not _same_weights_layout(init_config.backbone, self.config.model.backbone):
            raise SimdiffError(f"{folder}: backbone config differs from this run's model config")
        if init_config.text_encoder != self.config.model.text_encoder:
            raise SimdiffError(f"{folder}: text encoder {init_config.text_encoder!r} differs from this run's "
                               f"{self.config.model.text_encoder!r}")
        target = self.network.backbone if isinstance(self.network, SimDiffNet) else self.network
        target.load_state_dict(backbone.state_dict())
        return extra.get("normalizer.mean"), extra.get("normalizer.std")

    def _load_adapters(self, folder: Path) -> None:
        network, init_config, _ = load_pretrained(folder, "cpu")
        if not isinstance(network, SimDiffNet) or init_config.sim is None:
            raise SimdiffError(f"{folder}: not a SimDiff model (no Sim Encoder or adapters to start from)")
        if dataclasses.asdict(init_config.sim) != dataclasses.asdict(self.config.model.sim):
            raise SimdiffError(f"{folder}: sim config differs from this run's "
                               f"({init_config.sim} vs {self.config.model.sim})")
        if not _same_weights_layout(init_config.backbone, self.config.model.backbone):
            raise SimdiffError(f"{folder}: backbone config differs from this run's model config")
        own = self.network.state_dict()
        own.update({k: v for k, v in network.state_dict().items() if not k.startswith("backbone.")})
        self.network.load_state_dict(own)

    def _normalizer(self, mean: Tensor | None, std: Tensor | None, init_mean: Tensor | None,
                    init_std: Tensor | None) -> tuple[Tensor, Tensor]:
        norm = getattr(self.dataset, "normalizer", None)
        n = self.config.model.backbone.nfeats
        if mean is None:
            mean = torch.as_tensor(np.asarray(norm.mean)) if norm is not None else init_mean
        if std is None:
            std = torch.as_tensor(np.asarray(norm.std)) if norm is not None else init_std
        mean = torch.zeros(n) if mean is None else mean
        std = torch.ones(n) if std is None else std
        return mean.float().cpu(), std.float().cpu()

    def _restore(self, folder: Path) -> dict[str, Tensor] | None:
        step, model_tensors, optim_state, ema_state, run = read_checkpoint(folder)
        if run.get("model") != dataclasses.asdict(self.config.model):
            raise SimdiffError(f"{folder}: checkpoint was trained with another model config; use a new run folder")
        own = set(self.network.state_dict())
        self.network.load_state_dict({k: v for k, v in model_tensors.items() if k in own}, strict=True)
        self.mean = model_tensors.get("normalizer.mean", self.mean)
        self.std = model_tensors.get("normalizer.std", self.std)
        self.optimizer.load_state_dict(optim_state)
        self.step = step
        return ema_state

    # --- training ---------------------------------------------------------------------------

    def batch(self, step: int) -> dict[str, Any]:
        """The collated batch of step ``step`` for this process."""
        return self._step_batches().batch(step)

    def _step_batches(self, start: int = 0, end: int = 0) -> StepBatches:
        tc = self.config.train
        return StepBatches(self.dataset, self.batcher, tc.seed, self.rank, tc.crop, start, end, pairs=tc.env_pairs > 0)

    def _batches(self, end: int) -> Iterator[dict[str, Any]]:
        """Batches of steps ``self.step .. end - 1`` in order: built here, or ahead by ``loader_workers`` processes."""
        if self.loader_workers <= 0:
            source = self._step_batches()
            for step in range(self.step, end):
                yield source.batch(step)
            return
        loader = torch.utils.data.DataLoader(self._step_batches(self.step, end), batch_size=None, shuffle=False,
                                             num_workers=self.loader_workers, prefetch_factor=4,
                                             pin_memory=self.device.type == "cuda")
        yield from loader

    def condition(self, batch: dict[str, Any], generator: torch.Generator) -> Condition:
        """Text vectors with per-sample dropout (p = ``cond_mask_prob``) and φ (never dropped).

        Paired batches (``batch["paired"]``) drop the text of both twins alike.
        """
        b = len(batch["captions"])
        if "paired" in batch:
            uncond = (torch.rand(b // 2, generator=generator) < self.config.train.cond_mask_prob).repeat(2)
        else:
            uncond = torch.rand(b, generator=generator) < self.config.train.cond_mask_prob
        env = env_index = None
        sim = self.config.model.sim
        if sim is not None:
            key = "env" if sim.mode == "continuous" else "env_index"
            if key not in batch:
                raise SimdiffError(f"adapter training needs an {key!r} entry in every dataset item")
            env = batch.get("env") if sim.mode == "continuous" else None
            env_index = batch.get("env_index") if sim.mode == "categorical" else None
        mv = lambda v: None if v is None else v.to(self.device)  # noqa: E731
        return Condition(text=self.text.encode(batch["captions"]), uncond=uncond.to(self.device),
                         frame_mask=batch["mask"].to(self.device), env=mv(env), env_index=mv(env_index), alpha=1.0)

    def train_step(self, batch: dict[str, Any] | None = None) -> float:
        """One optimiser step on ``batch`` (default: this step's batch, built here); returns the (local) loss."""
        tc = self.config.train
        self.model.train()
        if batch is None:
            batch = self.batch(self.step)
        data_seed, dropout_seed = _seeds(tc.seed, self.step, self.rank)
        generator = torch.Generator().manual_seed(data_seed)
        cond = self.condition(batch, generator)
        torch.manual_seed(dropout_seed)
        x0 = batch["motion"].to(self.device)
        mask = batch["mask"].to(self.device)
        if "paired" in batch:
            self.network.backbone.eval()  # frozen: no dropout, so twins differ only through φ
            pred = self._paired_prediction(x0, cond, generator, batch["paired"], batch["captions"])
        else:
            pred = diffusion_prediction(self.model, self.scheduler, x0, cond, generator=generator)
        loss = masked_mse(pred, x0, mask)
        if tc.losses.active:
            loss = loss + geometric_loss(pred, x0, mask, self.mean, self.std, tc.losses)
        if "paired" in batch:
            paired = windy = batch["paired"].to(self.device)
            if "env" in batch and "wind" in (tc.pair_twins, tc.drift_pairs):  # twins whose φ differ in wind
                env, h = batch["env"], x0.shape[0] // 2
                windy = paired & (env[:h, 1:] != env[h:, 1:]).any(dim=-1).to(self.device)
            loss = loss + tc.env_pairs * self._pair_loss(pred, x0, mask, windy if tc.pair_twins == "wind" else paired)
            if tc.env_pairs_drift > 0:
                loss = loss + tc.env_pairs_drift * twin_drift_mse(pred, x0, mask,
                                                                  windy if tc.drift_pairs == "wind" else paired)
        self.optimizer.zero_grad(set_to_none=True)
        loss.backward()
        for group in self.optimizer.param_groups:
            group["lr"] = lr_at(tc.optim, self.step, tc.steps)
        if tc.optim.grad_clip > 0:
            nn.utils.clip_grad_norm_(list(self.trainable.values()), tc.optim.grad_clip)
        self.optimizer.step()
        if self.ema is not None:
            self.ema.update(self.step)
        self.step += 1
        value = float(loss.detach())
        if not math.isfinite(value):
            raise SimdiffError(f"loss became {value} at step {self.step}")
        return value

    def _paired_prediction(self, x0: Tensor, cond: Condition, generator: torch.Generator,
                           paired: Tensor | None = None, captions: Sequence[str] | None = None) -> Tensor:
        """x̂₀ (B, T, F) with one t and one ε per twin pair (items i and i + B/2). With ``cross_twins`` p > 0, a share p
        of the paired twins (``paired`` (B/2,) bool) are noised from each other's x₀ (``TrainConfig.cross_twins``);
        with ``cross_match``, only pairs whose first twin's caption (``captions``, B) matches it."""
        h = x0.shape[0] // 2
        t = torch.randint(0, self.scheduler.num_train_timesteps, (h,), generator=generator).repeat(2).to(self.device)
        noise = torch.randn((h, *x0.shape[1:]), generator=generator).repeat(2, 1, 1).to(self.device)
        source = x0
        p = self.config.train.cross_twins
        if p > 0:
            cross = torch.rand(h, generator=generator) < p
            if paired is not None:
                cross &= paired.cpu()
            if self._cross_match is not None:
                if captions is None:
                    raise SimdiffError("cross_match needs the batch's captions")
                cross &= torch.tensor([bool(self._cross_match.search(c)) for c in captions[:h]])
            cross = cross.to(self.device)[:, None, None]
            swapped = torch.cat([x0[h:], x0[:h]])
            source = torch.where(cross.repeat(2, 1, 1), swapped, x0)
        return self.model(self.scheduler.add_noise(source, noise, t), t, cond)

    @staticmethod
    def _pair_loss(pred: Tensor, x0: Tensor, mask: Tensor, paired: Tensor) -> Tensor:
        """MSE between predicted and true twin differences over the valid frames of paired twins (0 when none)."""
        return twin_difference_mse(pred, x0, mask, paired)

    def train(self, until: int | None = None, progress: bool = True,
              on_step: Callable[[int, float], None] | None = None,
              stop: Callable[[], bool] | None = None) -> list[float]:
        """Train up to ``until`` (default ``config.train.steps``) steps, checkpointing on the way.

        ``stop`` is asked at every checkpoint (every 100 steps when ``save_every`` is 0); ``True`` ends the call
        there. Returns the losses of the steps run in this call.
        """
        tc = self.config.train
        end = min(tc.steps, until) if until is not None else tc.steps
        bar = None
        if progress and self.rank == 0:
            from tqdm.auto import tqdm

            bar = tqdm(total=tc.steps, initial=self.step, desc=f"train {tc.mode}", unit="step", dynamic_ncols=True)
        losses: list[float] = []
        window: list[float] = []
        batches = self._batches(end)
        while self.step < end:
            value = self.train_step(next(batches))
            losses.append(value)
            window = (window + [value])[-max(1, tc.log_every):]
            if bar is not None:
                bar.update(1)
                bar.set_postfix(loss=f"{sum(window) / len(window):.4f}")
            if self.rank == 0 and (self.step % max(1, tc.log_every) == 0 or self.step == end):
                self._log(sum(window) / len(window))
            if on_step is not None:
                on_step(self.step, value)
            if tc.save_every and self.step % tc.save_every == 0:
                self.save()
            if stop is not None and self.step % (tc.save_every or 100) == 0 and stop():
                break
        batches.close()
        if bar is not None:
            bar.close()
        if self._saved_step != self.step:
            self.save()
        self.history.extend(losses)
        return losses

    def train_for(self, max_minutes: float, progress: bool = True) -> list[float]:
        """Train to ``config.train.steps``, or stop at the first checkpoint after ``max_minutes`` of wall clock.

        ``max_minutes <= 0`` means no limit. The run stays resumable. Returns the losses of the steps run in this call.
        """
        if max_minutes <= 0:
            return self.train(progress=progress)
        deadline = time.monotonic() + 60.0 * max_minutes
        return self.train(progress=progress, stop=lambda: time.monotonic() >= deadline)

    # --- output -----------------------------------------------------------------------------

    def _log(self, loss: float) -> None:
        """Append ``{"step", "loss"}`` (loss averaged over the last ``log_every`` steps) to ``train_log.jsonl``."""
        self.run_dir.mkdir(parents=True, exist_ok=True)
        with open(self.run_dir / "train_log.jsonl", "a", encoding="utf-8") as f:
            f.write(json.dumps({"step": self.step, "loss": round(loss, 6)}) + "\n")

    def extra_tensors(self) -> dict[str, Tensor]:
        return {"normalizer.mean": self.mean, "normalizer.std": self.std}

    def export_state(self) -> dict[str, Tensor]:
        """Weights for inference: the EMA average when EMA is on, else the raw weights."""
        state = self.network.state_dict()
        return self.ema.averaged_state(state) if self.ema is not None else dict(state)

    def save(self) -> None:
        """Checkpoint (resumable) and export ``run_dir/model`` (inference). Rank 0 writes; all wait."""
        self._saved_step = self.step
        if self.rank == 0:
            run = dataclasses.asdict(self.config)
            write_checkpoint(self.run_dir, self.step, {**self.network.state_dict(), **self.extra_tensors()},
                             dataclasses.asdict(self.config.model), self.optimizer.state_dict(),
                             self.ema.state_dict() if self.ema is not None else None, run,
                             keep=self.config.train.keep_checkpoints)
            exported = build_network(self.config.model)
            exported.load_state_dict(self.export_state())
            save_pretrained(self.run_dir / "model", exported, self.config.model, self.extra_tensors())
            if self.provenance is not None:
                write_provenance(self.run_dir / "model", self.provenance)
            from simdiff.model.checkpoint import atomic_write_json

            atomic_write_json(run, self.run_dir / "train_config.json")
            self.text.save(self.run_dir / TEXT_CACHE)
        if self.world_size > 1:
            import torch.distributed as dist

            dist.barrier()
