"""Learning curves per CPU-hour: train a named design in chunks and evaluate it between chunks.

Each point: training CPU seconds (``time.process_time`` over the training chunks only, all
threads), step, mean train loss of the chunk, held-out loss (x₀ MSE on a fixed held-out
batch with fixed t and ε), and of DDIM samples for the held-out captions at their GT lengths:
sliding (mm/frame) and skate ratio (:mod:`simdiff.motion.metrics`), and R@3 with our
evaluator when one is given (else ``None``). ``benchmarks/train_curves.py`` is the CLI.
"""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

import numpy as np
import torch

from simdiff.errors import SimdiffError
from simdiff.model.config import ModelConfig, backbone_preset
from simdiff.train.config import OptimConfig, RunConfig, TrainConfig
from simdiff.train.geometric import CropConfig, GeometricLossConfig

_GEO = GeometricLossConfig(velocity=1.0, foot_contact=1.0)
_CROP = CropConfig(max_frames=120, trim_padding=True)
DESIGNS: dict[str, dict[str, Any]] = {
    "small_plain": dict(size="small", batch_size=32, lr=1e-4, losses=GeometricLossConfig(), crop=CropConfig()),
    "small_geo_crop": dict(size="small", batch_size=64, lr=2e-4, losses=_GEO, crop=_CROP),
    "mdm_geo_crop": dict(size="mdm", batch_size=64, lr=1e-4, losses=_GEO, crop=_CROP),
    "small_lowfps2": dict(size="small", batch_size=64, lr=2e-4, losses=_GEO, crop=CropConfig(max_frames=60, trim_padding=True),
                          factor=2),
    "tiny_plain": dict(size="tiny", batch_size=8, lr=1e-3, losses=GeometricLossConfig(), crop=CropConfig()),
    "tiny_lowfps2": dict(size="tiny", batch_size=8, lr=1e-3, losses=GeometricLossConfig(), crop=CropConfig(), factor=2),
}
"""Named backbone/training designs: MDM's transformer (``mdm`` 8×512 or ``small`` 4×256) with or
without MDM's velocity/foot-contact losses and 120-frame crops; ``factor`` 2: the cheaper design,
trained at 10 fps and upsampled to 20 fps (:mod:`simdiff.train.lowfps`). ``tiny_*`` for smoke tests."""


def design_factor(name: str) -> int:
    """Frame-rate reduction of design ``name`` (1: trained at 20 fps)."""
    return int(DESIGNS.get(name, {}).get("factor", 1))


def design_config(name: str, text_encoder: str, text_dim: int, seed: int, steps: int = 10**9) -> RunConfig:
    """The backbone :class:`RunConfig` of design ``name``."""
    if name not in DESIGNS:
        raise SimdiffError(f"unknown design {name!r}; choose one of {', '.join(DESIGNS)}")
    d = DESIGNS[name]
    model = ModelConfig(backbone=backbone_preset(d["size"], text_dim=text_dim), text_encoder=text_encoder)
    train = TrainConfig(mode="backbone", steps=steps, batch_size=d["batch_size"], seed=seed, ema=True, ema_decay=0.999,
                        save_every=0, optim=OptimConfig(lr=d["lr"]), losses=dataclasses.replace(d["losses"]),
                        crop=dataclasses.replace(d["crop"]))
    return RunConfig(model=model, train=train)


@dataclass
class HeldOut:
    """A fixed held-out batch (collated: normalised motion, lengths, mask, captions) and its GT metrics."""

    batch: dict[str, Any]
    gt: dict[str, float]


def held_out(dataset: Any, n: int, seed: int, evaluator: Any = None, factor: int = 1) -> HeldOut:
    """``n`` held-out items drawn with a fixed seed, and the GT's sliding, skate ratio (and R@3).

    With ``factor`` > 1 (a low-frame-rate dataset) the GT metrics are those of the GT upsampled
    to 20 fps, the floor the design can reach.
    """
    from simdiff.train.data import collate

    rng = np.random.default_rng([seed, 99])
    idx = rng.permutation(len(dataset))[:n]
    batch = collate([dataset.get(int(i), rng) for i in idx])
    raw = dataset.normalizer.denormalize(batch["motion"]) * batch["mask"][..., None]
    batch["raw"] = raw
    return HeldOut(batch, _sample_metrics(raw, batch, evaluator, factor))


def _upsample_batch(raw: torch.Tensor, lengths: torch.Tensor, factor: int) -> tuple[torch.Tensor, torch.Tensor]:
    """Low-rate (B, L, 263) raw features → 20 fps (B, L·factor, 263) and their lengths."""
    from simdiff.train.lowfps import upsample_features

    ups = [upsample_features(raw[i, : int(n)].double().cpu().numpy(), factor) for i, n in enumerate(lengths)]
    out = torch.zeros(len(ups), max(len(u) for u in ups), raw.shape[-1])
    for i, u in enumerate(ups):
        out[i, : len(u)] = torch.from_numpy(np.asarray(u, dtype=np.float32))
    return out, torch.tensor([len(u) for u in ups])


def _sample_metrics(raw: torch.Tensor, batch: dict[str, Any], evaluator: Any, factor: int = 1) -> dict[str, float]:
    from simdiff.motion.features import features_to_joints
    from simdiff.motion.metrics import physics_metrics

    lengths = batch["lengths"]
    if factor > 1:
        raw, lengths = _upsample_batch(raw, lengths, factor)
    joints = features_to_joints(raw.detach().double().cpu())
    phys = physics_metrics(joints.numpy(), lengths.cpu().clamp(min=2).numpy())
    out: dict[str, Any] = {"sliding": phys["sliding"], "skate_ratio": phys["skate_ratio"], "r_precision_top3": None}
    if evaluator is not None:
        from simdiff.eval.metrics import matching_metrics

        n = len(lengths)
        t = evaluator.embed_text(batch["captions"])
        m = evaluator.embed_motion(raw.float(), lengths)
        out["r_precision_top3"] = float(matching_metrics(t, m, batch_size=min(32, n)).r_precision[2])
    return out


@torch.no_grad()
def heldout_loss(trainer: Any, held: HeldOut, draws: int = 4) -> float:
    """Mean x₀ MSE of the trainer's (raw) network on the held-out batch over ``draws`` fixed (t, ε)."""
    from simdiff.diffusion.losses import diffusion_prediction, masked_mse
    from simdiff.model.condition import Condition

    net = trainer.network
    was = net.training
    net.eval()
    b = held.batch
    x0, mask = b["motion"].to(trainer.device), b["mask"].to(trainer.device)
    cond = Condition(text=trainer.text.encode(b["captions"]), uncond=torch.zeros(len(mask), dtype=torch.bool, device=trainer.device),
                     frame_mask=mask)
    total = 0.0
    for k in range(draws):
        g = torch.Generator().manual_seed(1000 + k)
        total += float(masked_mse(diffusion_prediction(net, trainer.scheduler, x0, cond, generator=g), x0, mask))
    net.train(was)
    return total / draws


def draw_samples(trainer: Any, held: HeldOut, steps: int, guidance: float) -> torch.Tensor:
    """DDIM samples (the exported, EMA weights) for the held-out captions at their lengths: (N, L, 263) raw features."""
    from simdiff.model.checkpoint import build_network
    from simdiff.model.generator import MotionGenerator

    net = build_network(trainer.config.model)
    net.load_state_dict(trainer.export_state())
    gen = MotionGenerator(net, trainer.config.model, trainer.text, trainer.mean, trainer.std, trainer.device)
    lengths = [int(n) for n in held.batch["lengths"]]
    return gen.generate(held.batch["captions"], lengths, steps=steps, guidance=guidance, seed=0).features.cpu()


def sample_metrics(trainer: Any, held: HeldOut, evaluator: Any, steps: int, guidance: float,
                   factor: int = 1) -> dict[str, float]:
    """Metrics of DDIM samples (the exported, EMA weights) for the held-out captions and lengths."""
    feats = draw_samples(trainer, held, steps, guidance)
    return _sample_metrics(feats, held.batch, evaluator, factor)


def score_samples(feats: torch.Tensor, held: HeldOut, evaluator: Any, factor: int = 1) -> dict[str, float]:
    """The sample metrics of saved samples ``feats`` (N, L, 263) raw features (e.g. R@3 once an evaluator exists)."""
    return _sample_metrics(feats, held.batch, evaluator, factor)


POINTS_NAME = "curve_points.jsonl"
"""Per-run log of the points (one JSON object per line), so a run continues where it stopped."""


def _sample_path(run_dir: Path, step: int) -> Path:
    return run_dir / "curve_samples" / f"step_{step:07d}.npy"


def load_points(run_dir: Path | None) -> list[dict[str, Any]]:
    """Points already measured in ``run_dir`` (empty without one)."""
    import json

    path = None if run_dir is None else Path(run_dir) / POINTS_NAME
    if path is None or not path.is_file():
        return []
    return [json.loads(line) for line in path.read_text().splitlines() if line.strip()]


def rescore(run_dir: Path, held: HeldOut, evaluator: Any, factor: int = 1) -> list[dict[str, Any]]:
    """Recompute the sample metrics of every saved point of ``run_dir`` (R@3 with ``evaluator``); rewrites the log."""
    import json

    from simdiff.fsio import write_text

    rows = load_points(run_dir)
    for row in rows:
        path = _sample_path(Path(run_dir), int(row["step"]))
        if not path.is_file():
            raise SimdiffError(f"{path}: no saved samples for step {row['step']}; cannot rescore")
        row.update(score_samples(torch.from_numpy(np.load(path)), held, evaluator, factor))
    write_text(Path(run_dir) / POINTS_NAME, "".join(json.dumps(r) + "\n" for r in rows))
    return rows


def run_curve(trainer: Any, held: HeldOut, minutes: float, points: int, *, evaluator: Any = None,
              sample_steps: int = 20, guidance: float = 2.5, factor: int = 1, save: bool = False,
              log: Callable[[str], None] = print) -> list[dict[str, Any]]:
    """Train until ``minutes`` of CPU time (training only), evaluating ``points`` times evenly; returns all points.

    With ``save`` the trainer checkpoints at every point and the points and samples are logged
    in its run folder: a later call with a larger ``minutes`` continues from the last point
    (CPU time counted from there) and returns the earlier points too.
    """
    import json

    from simdiff.fsio import atomic_path, write_text

    budget = 60.0 * minutes
    rows = load_points(trainer.run_dir) if save else []
    if rows and int(rows[-1]["step"]) != trainer.step:
        raise SimdiffError(f"{trainer.run_dir}: last logged point is step {rows[-1]['step']} but the checkpoint is at "
                           f"step {trainer.step}; use a new run folder")
    cpu = float(rows[-1]["cpu_s"]) if rows else 0.0
    wall = float(rows[-1]["wall_s"]) if rows else 0.0
    start = cpu
    for p in range(1, points + 1):
        target = start + (budget - start) * p / points
        if target <= cpu:
            continue
        losses: list[float] = []
        while cpu < target:
            c0, w0 = time.process_time(), time.perf_counter()
            losses.append(trainer.train_step())
            cpu += time.process_time() - c0
            wall += time.perf_counter() - w0
        row = {"step": trainer.step, "cpu_s": round(cpu, 2), "cpu_h": cpu / 3600.0, "wall_s": round(wall, 2),
               "train_loss": float(np.mean(losses)) if losses else None, "heldout_loss": heldout_loss(trainer, held)}
        feats = draw_samples(trainer, held, sample_steps, guidance)
        row.update(_sample_metrics(feats, held.batch, evaluator, factor))
        rows.append(row)
        if save:
            trainer.save()
            path = _sample_path(trainer.run_dir, trainer.step)
            path.parent.mkdir(parents=True, exist_ok=True)
            with atomic_path(path) as tmp:
                with open(tmp, "wb") as fh:
                    np.save(fh, feats.cpu().numpy().astype(np.float32))
            write_text(trainer.run_dir / POINTS_NAME, "".join(json.dumps(r) + "\n" for r in rows))
        log(" ".join(f"{k}={v:.4g}" if isinstance(v, float) else f"{k}={v}" for k, v in row.items()))
    return rows


def plot_curves(curves: dict[str, Any], path: str | Path) -> Path:
    """A 2×2 PNG (held-out loss, sliding, skate ratio, R@3 against training CPU-hours), one line per design."""
    from PIL import Image, ImageDraw

    from simdiff.fsio import atomic_path

    panels = [("heldout_loss", "held-out loss"), ("sliding", "sliding mm/frame"), ("skate_ratio", "skate ratio"),
              ("r_precision_top3", "R@3 (our evaluator)")]
    colours = [(31, 119, 180), (255, 127, 14), (44, 160, 44), (214, 39, 40), (148, 103, 189)]
    w, h, pad = 440, 300, 40
    img = Image.new("RGB", (2 * w, 2 * h), "white")
    draw = ImageDraw.Draw(img)
    for i, (key, title) in enumerate(panels):
        ox, oy = (i % 2) * w, (i // 2) * h
        draw.text((ox + pad, oy + 8), f"{title} vs CPU-hours", fill="black")
        series = {d: [(r["cpu_h"], r[key]) for r in c["points"] if r.get(key) is not None] for d, c in curves.items()}
        xs = [x for s in series.values() for x, _ in s]
        ys = [y for s in series.values() for _, y in s]
        draw.rectangle([ox + pad, oy + pad, ox + w - 10, oy + h - pad], outline="black")
        if not xs:
            draw.text((ox + pad + 10, oy + h // 2), "no data", fill="gray")
            continue
        x0, x1 = 0.0, max(xs) or 1.0
        y0, y1 = min(ys), max(ys)
        y1 = y1 if y1 > y0 else y0 + 1.0
        draw.text((ox + 2, oy + pad), f"{y1:.3g}", fill="black")
        draw.text((ox + 2, oy + h - pad - 10), f"{y0:.3g}", fill="black")
        draw.text((ox + w - 70, oy + h - pad + 4), f"{x1:.3g} h", fill="black")

        def at(x: float, y: float) -> tuple[float, float]:
            return (ox + pad + (x - x0) / (x1 - x0) * (w - pad - 10), oy + h - pad - (y - y0) / (y1 - y0) * (h - 2 * pad))

        for j, (design, pts) in enumerate(series.items()):
            colour = colours[j % len(colours)]
            xy = [at(x, y) for x, y in pts]
            if len(xy) > 1:
                draw.line(xy, fill=colour, width=2)
            for x, y in xy:
                draw.ellipse([x - 2, y - 2, x + 2, y + 2], fill=colour)
            draw.text((ox + pad + 6, oy + pad + 4 + 12 * j), design, fill=colour)
    with atomic_path(path) as tmp:
        img.save(tmp, format="PNG")
    return Path(path)
