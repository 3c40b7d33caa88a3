"""Train our text–motion evaluator on a corpus's train split (resumable, deterministic under a seed).

``out/`` receives ``model.safetensors`` + ``config.json`` (the best epoch on the validation
split by R-precision top-1, or the last epoch without one) and ``checkpoint/`` (weights,
optimiser, epoch, history; replaced atomically after every epoch).
"""

from __future__ import annotations

import dataclasses
import json
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import torch
from torch import Tensor

from simdiff.errors import SimdiffError
from simdiff.eval.evaluator import EvaluatorConfig, TextMotionEvaluator, save_evaluator
from simdiff.eval.metrics import matching_metrics


@dataclass
class EvaluatorTrainConfig:
    """Training options.

    Attributes:
        evaluator: architecture.
        epochs: passes over the train split.
        batch_size: pairs per step (T2M: 32).
        lr: Adam learning rate (T2M: 1e-4; 1e-3 trains a small evaluator faster on CPU).
        margin: negative margin of the contrastive loss (T2M: 10).
        grad_clip: gradient-norm clip (T2M: 0.5).
        seed: seeds init, order, captions/crops and negatives.
        split, val_split: split files of the corpus (``val_split`` skipped when absent/empty).
    """

    evaluator: EvaluatorConfig = field(default_factory=EvaluatorConfig)
    epochs: int = 30
    batch_size: int = 32
    lr: float = 1e-3
    margin: float = 10.0
    grad_clip: float = 0.5
    seed: int = 0
    split: str = "train"
    val_split: str = "val"


def contrastive_loss(text: Tensor, motion: Tensor, captions: list[str], margin: float, shift: int) -> Tensor:
    """Guo et al.'s loss: ``d(t_i, m_i)²`` + ``max(0, margin − d(t_i, m_{i+shift}))²`` (same-caption negatives skipped)."""
    pos = (text - motion).norm(dim=-1)
    neg_motion = torch.roll(motion, shifts=shift, dims=0)
    neg = (text - neg_motion).norm(dim=-1)
    shifted = captions[-shift:] + captions[:-shift]
    valid = torch.tensor([a != b for a, b in zip(captions, shifted)], dtype=text.dtype, device=text.device)
    neg_term = (torch.relu(margin - neg) ** 2 * valid).sum() / valid.sum().clamp(min=1.0)
    return (pos**2).mean() + neg_term


def _batch(dataset: Any, indices: list[int], rng: np.random.Generator) -> dict[str, Any]:
    from simdiff.data.batch import collate

    return collate([dataset.get(i, rng) for i in indices])


def evaluate_matching(model: TextMotionEvaluator, dataset: Any, text_encoder: Any, seed: int, batch_size: int = 32) -> dict[str, float]:
    """R-precision top-1..3 and MM-Dist of ``dataset`` under ``model`` (fixed captions/crops from ``seed``)."""
    model.eval()
    n = len(dataset)
    bs = min(batch_size, n)
    rng = np.random.default_rng([seed, 7])
    texts, motions = [], []
    with torch.no_grad():
        for start in range(0, n - n % bs, bs):
            b = _batch(dataset, list(range(start, start + bs)), rng)
            raw = dataset.normalizer.denormalize(b["motion"])
            motions.append(model.embed_motion(raw, b["lengths"]).double().cpu().numpy())
            texts.append(model.embed_text_vectors(text_encoder.encode(b["captions"])).double().cpu().numpy())
    stats = matching_metrics(np.concatenate(texts), np.concatenate(motions), batch_size=bs)
    top = stats.r_precision
    return {"top1": float(top[0]), "top2": float(top[1]), "top3": float(top[2]), "mm_dist": stats.mm_dist, "batch": bs}


def _save_checkpoint(folder: Path, model: TextMotionEvaluator, optim: torch.optim.Optimizer, meta: dict[str, Any]) -> None:
    from simdiff.fsio import atomic_save_tensors
    from simdiff.model.checkpoint import atomic_write_json
    from simdiff.model.optimizer_state import optimizer_to_flat

    opt_tensors, opt_meta = optimizer_to_flat(optim.state_dict())
    tensors = {f"model.{k}": v for k, v in model.state_dict().items()} | opt_tensors
    atomic_save_tensors(tensors, folder / "state.safetensors")
    atomic_write_json({**meta, "optimizer": opt_meta}, folder / "state.json")


def _load_checkpoint(folder: Path, model: TextMotionEvaluator, optim: torch.optim.Optimizer) -> dict[str, Any] | None:
    from safetensors.torch import load_file

    from simdiff.model.optimizer_state import optimizer_from_flat

    if not (folder / "state.json").is_file() or not (folder / "state.safetensors").is_file():
        return None
    meta = json.loads((folder / "state.json").read_text(encoding="utf-8"))
    tensors = load_file(str(folder / "state.safetensors"))
    model.load_state_dict({k[6:]: v for k, v in tensors.items() if k.startswith("model.")})
    optim.load_state_dict(optimizer_from_flat(tensors, meta["optimizer"]))
    return meta


def train_evaluator(corpus: str | os.PathLike[str], out: str | os.PathLike[str],
                    config: EvaluatorTrainConfig = EvaluatorTrainConfig(), *, text_encoder: Any = None,
                    device: torch.device | str = "cpu", progress: bool = True) -> dict[str, Any]:
    """Train (or resume) an evaluator on ``corpus`` and export it to ``out``; returns the summary.

    Args:
        corpus: HumanML3D-layout corpus (only ``config.split`` and ``config.val_split`` are read).
        out: output folder.
        text_encoder: sentence encoder (default MiniLM); wrapped in a cache.
    """
    from tqdm import tqdm

    from simdiff.data.humanml3d import HumanML3D
    from simdiff.text.cache import CachedTextEncoder

    corpus, out = Path(corpus), Path(out)
    if config.split == "test" or config.val_split == "test":
        raise SimdiffError("the evaluator must not see the test split")
    if config.epochs < 1 or config.batch_size < 2:
        raise SimdiffError("epochs must be >= 1 and batch size >= 2")
    train = HumanML3D(corpus, config.split, seed=config.seed)
    if len(train) < 2:
        raise SimdiffError(f"{corpus}: the {config.split} split has fewer than 2 usable clips")
    val = None
    val_file = corpus / f"{config.val_split}.txt"
    if val_file.is_file() and val_file.read_text().strip():
        val = HumanML3D(corpus, config.val_split, normalizer=train.normalizer, seed=config.seed)
        val = val if len(val) >= 2 else None
    device = torch.device(device)
    torch.manual_seed(config.seed)
    norm = train.normalizer
    model = TextMotionEvaluator(config.evaluator, torch.from_numpy(norm.mean), torch.from_numpy(norm.std)).to(device)
    optim = torch.optim.Adam(model.parameters(), lr=config.lr)
    if text_encoder is None:
        from simdiff.text.base import load_text_encoder

        text_encoder = load_text_encoder(config.evaluator.text_encoder, device)
    text = CachedTextEncoder(text_encoder, device)
    from simdiff.model.provenance import provenance_from_corpus, write_provenance

    provenance = provenance_from_corpus(corpus, "evaluator", split=config.split)  # out/provenance.json
    ckpt = out / "checkpoint"
    meta = _load_checkpoint(ckpt, model, optim)
    if meta is not None and meta.get("config") != json.loads(json.dumps(dataclasses.asdict(config))):
        raise SimdiffError(f"{out} holds a run with a different config; use a new --out")
    start = 0 if meta is None else int(meta["epoch"])
    history: list[dict[str, Any]] = [] if meta is None else meta["history"]
    best = -1.0 if meta is None else float(meta["best"])
    bs = min(config.batch_size, len(train))
    steps = len(train) // bs
    bar = tqdm(range(start, config.epochs), desc="evaluator", unit="epoch", disable=not progress, dynamic_ncols=True)
    for epoch in bar:
        model.train()
        torch.manual_seed(config.seed * 1_000_003 + epoch)  # dropout stream per epoch, so a resumed run matches
        perm = torch.randperm(len(train), generator=torch.Generator().manual_seed(config.seed * 100_003 + epoch)).tolist()
        rng = np.random.default_rng([config.seed, epoch])
        neg = np.random.default_rng([config.seed, epoch, 1])
        losses = []
        for s in range(steps):
            b = _batch(train, perm[s * bs : (s + 1) * bs], rng)
            raw = norm.denormalize(b["motion"]).to(device)
            m = model.embed_motion(raw, b["lengths"])
            t = model.embed_text_vectors(text.encode(b["captions"]))
            loss = contrastive_loss(t, m, b["captions"], config.margin, int(neg.integers(1, bs)))
            optim.zero_grad(set_to_none=True)
            loss.backward()
            torch.nn.utils.clip_grad_norm_(model.parameters(), config.grad_clip)
            optim.step()
            losses.append(float(loss.detach()))
        row: dict[str, Any] = {"epoch": epoch + 1, "loss": float(np.mean(losses))}
        score = row["epoch"]  # without validation the last epoch wins
        if val is not None:
            row["val"] = evaluate_matching(model, val, text, config.seed)
            score = row["val"]["top1"]
        history.append(row)
        if score >= best:
            best = score
            save_evaluator(out, model, {"training": {"corpus": str(corpus), "epoch": epoch + 1, "seed": config.seed,
                                                     "split": config.split, "val": row.get("val")}})
            write_provenance(out, provenance)
        _save_checkpoint(ckpt, model, optim, {"epoch": epoch + 1, "best": best, "history": history,
                                              "config": dataclasses.asdict(config)})
        bar.set_postfix(loss=f"{row['loss']:.3f}", **({"val_top1": f"{row['val']['top1']:.3f}"} if "val" in row else {}))
    return {"epochs": config.epochs, "history": history, "best": best, "out": str(out)}
