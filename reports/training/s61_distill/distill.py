"""Two-teacher distillation of the adapters (session 61): the gravity answer of one model, the wind answer of another.

python distill.py --student-init S --gravity-teacher G --wind-teacher W --out RUN [--steps 400] [--seed 61]
                  [--gravity-gain 1.0] [--data AUG ...]

Every model must use the student's normaliser (checked). Batches are the adapter-training batches of ``--data``
(first_try split, source-anchored targets), noised at a random t; only their x_t, text, mask and φ are used. Each item's
φ = (g, w_x, w_y) is split into its gravity part φ_g = (g, 0, 0) and its wind part φ_w = (−9.81, w_x, w_y); the target is

    x̂₀* = E(x_t, c, Earth) + k·[G(x_t, c, φ_g) − G(x_t, c, Earth)] + [W(x_t, c, φ_w) − W(x_t, c, Earth)]

(the wind bracket only for items with wind; k ``--gravity-gain``, default 1; E ``--earth-teacher``, default G), so the
student's Earth motion is E's, its answer to gravity G's, its answer to wind W's, and to both their sum. E and W must
share the student's frozen backbone; G may have another (its answer is transplanted at the same x_t). With
``--flight-teacher F``, low-gravity items whose Earth motion (E's x̂₀ at that x_t) has a flight of ≥ ``--min-flight-s``
take F's gravity answer instead of G's: ballistic phases answer gravity, ground contact barely does. Text dropout p 0.1 as in training and the adapter strength α (``--alphas``: drawn per item; default 1 as in
training; sampling runs at 0.5), the same for student and teachers;
every network in eval mode (no dropout). The student runs on φ and on Earth with the same x_t; loss: masked MSE of
both x̂₀ against their targets (Earth: E(Earth)), plus ``--pairs`` λ × the MSE of the answer (x̂₀(φ) − x̂₀(Earth) against
x̂₀* − E(Earth)) and ``--drift`` μ × its mean root-velocity error on windy items (the trainer's twin losses, with the
Earth call as twin): the answer is a small part of x̂₀, and the plain MSE alone leaves it half learnt (D1).
The run is a ``Trainer`` run (checkpoints, resume, EMA export in RUN/model); steps are deterministic under the seed.
"""
from __future__ import annotations

import argparse
import dataclasses
from pathlib import Path

import torch

from simdiff.data.augment import open_training_dataset
from simdiff.diffusion.losses import masked_mse, twin_difference_mse, twin_drift_mse
from simdiff.model.checkpoint import load_pretrained, read_config
from simdiff.motion.features import features_to_joints
from simdiff.motion.flight import flight_stats
from simdiff.text.table import open_caption_table
from simdiff.train.config import RunConfig, lr_at
from simdiff.train.trainer import Trainer, _seeds

EARTH = -9.81


class DistillTrainer(Trainer):
    def __init__(self, *args, gravity_teacher: Path, wind_teacher: Path, earth_teacher: Path | None = None,
                 flight_teacher: Path | None = None, min_flight_s: float = 0.1,
                 gravity_gain: float = 1.0, pairs: float = 10.0,
                 drift: float = 20.0, alphas: tuple[float, ...] = (), **kw) -> None:
        super().__init__(*args, **kw)
        self.teachers = {}
        own = {k: v for k, v in self.network.state_dict().items() if k.startswith("backbone.")}
        self.min_flight_s = min_flight_s
        named = [("G", gravity_teacher), ("W", wind_teacher), ("E", earth_teacher or gravity_teacher)]
        for name, folder in named + ([("F", flight_teacher)] if flight_teacher is not None else []):
            net, _, extra = load_pretrained(folder, "cpu")
            if not (torch.equal(extra["normalizer.mean"], self.mean) and torch.equal(extra["normalizer.std"], self.std)):
                raise SystemExit(f"{folder}: another normaliser than the student's")
            theirs = {k: v for k, v in net.state_dict().items() if k.startswith("backbone.")}
            same = theirs.keys() == own.keys() and all(torch.equal(own[k].cpu(), theirs[k]) for k in own)
            # the Earth and wind teachers share the student's backbone; the gravity teacher may bring its own
            if not (same or name in ("G", "F")):
                raise SystemExit(f"{folder}: another backbone than the student's (only the gravity and flight teachers may)")
            self.teachers[name] = net.to(self.device).eval().requires_grad_(False)
        self.flying: list[tuple[int, int]] = []
        self.gain, self.pairs, self.drift, self.alphas = gravity_gain, pairs, drift, tuple(alphas)

    def _flies(self, x: torch.Tensor, mask: torch.Tensor) -> torch.Tensor:
        """(B,) bool: the motion x̂₀ (B, T, 263, normalised) has a flight of at least ``min_flight_s`` on its valid frames."""
        joints = features_to_joints(x.detach().cpu().double() * self.std.double() + self.mean.double()).numpy()
        lengths = mask.sum(dim=1).tolist()  # frames integrate forward, so padding does not touch the valid ones
        return torch.tensor([n >= 2 and flight_stats(j[:n])["flight_s"] >= self.min_flight_s
                             for j, n in zip(joints, lengths)], device=x.device)

    def train_step(self, batch=None) -> float:
        tc = self.config.train
        if batch is None:
            batch = self.batch(self.step)
        data_seed, _ = _seeds(tc.seed, self.step, self.rank)
        gen = torch.Generator().manual_seed(data_seed)
        cond = self.condition(batch, gen)
        if self.alphas:  # adapter strength per item, the same for student and teachers
            pick = torch.randint(0, len(self.alphas), (len(batch["captions"]),), generator=gen)
            cond = dataclasses.replace(cond, alpha=torch.tensor(self.alphas, device=self.device)[pick.to(self.device)])
        x0 = batch["motion"].to(self.device)
        mask = batch["mask"].to(self.device)
        b = x0.shape[0]
        t = torch.randint(0, self.scheduler.num_train_timesteps, (b,), generator=gen).to(self.device)
        noise = torch.randn(x0.shape, generator=gen).to(self.device)
        xt = self.scheduler.add_noise(x0, noise, t)
        env = cond.env
        earth = torch.tensor([EARTH, 0.0, 0.0], device=self.device).expand(b, 3)
        env_g = torch.stack([env[:, 0], torch.zeros_like(env[:, 0]), torch.zeros_like(env[:, 0])], dim=-1)
        env_w = torch.cat([torch.full_like(env[:, :1], EARTH), env[:, 1:]], dim=-1)
        windy = (env[:, 1:].abs() > 1e-6).any(dim=-1)
        with torch.no_grad():
            G, W, E = self.teachers["G"], self.teachers["W"], self.teachers["E"]
            both = G(torch.cat([xt, xt]), t.repeat(2), dataclasses.replace(cond, env=env_g).stacked(
                dataclasses.replace(cond, env=earth)))
            t_earth = both[b:] if E is G else E(xt, t, dataclasses.replace(cond, env=earth))
            t_phi = t_earth + self.gain * (both[:b] - both[b:])
            lowg = (env[:, 0] - EARTH).abs() > 1e-6
            if "F" in self.teachers and bool(lowg.any()):  # items whose Earth motion flies: F's gravity answer
                fly = lowg.clone()
                fly[lowg] = self._flies(t_earth[lowg], mask[lowg])  # only the low-gravity rows are tested
                if bool(fly.any()):
                    rows = fly.nonzero().flatten()
                    sub, k = cond.select(rows), len(rows)
                    pair = self.teachers["F"](torch.cat([xt[rows], xt[rows]]), t[rows].repeat(2),
                                              dataclasses.replace(sub, env=env_g[rows]).stacked(
                                                  dataclasses.replace(sub, env=earth[rows])))
                    t_phi[rows] = t_earth[rows] + self.gain * (pair[:k] - pair[k:])
                self.flying.append((int(fly.sum()), int(lowg.sum())))
            if bool(windy.any()):
                rows = windy.nonzero().flatten()
                sub = cond.select(rows)
                pair = W(torch.cat([xt[rows], xt[rows]]), t[rows].repeat(2),
                         dataclasses.replace(sub, env=env_w[rows]).stacked(dataclasses.replace(sub, env=earth[rows])))
                k = len(rows)
                t_phi[rows] = t_phi[rows] + pair[:k] - pair[k:]
        self.network.eval()
        pred = self.network(torch.cat([xt, xt]), t.repeat(2), cond.stacked(dataclasses.replace(cond, env=earth)))
        target, mask2 = torch.cat([t_phi, t_earth]), torch.cat([mask, mask])
        loss = masked_mse(pred, target, mask2)
        if self.pairs > 0:
            loss = loss + self.pairs * twin_difference_mse(pred, target, mask2, torch.ones(b, dtype=torch.bool, device=self.device))
        if self.drift > 0:
            loss = loss + self.drift * twin_drift_mse(pred, target, mask2, windy)
        self.optimizer.zero_grad(set_to_none=True)
        loss.backward()
        for group in self.optimizer.param_groups:
            group["lr"] = lr_at(tc.optim, self.step, tc.steps)
        self.optimizer.step()
        if self.ema is not None:
            self.ema.update(self.step)
        self.step += 1
        return float(loss.detach())


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--student-init", type=Path, required=True)
    p.add_argument("--gravity-teacher", type=Path, required=True)
    p.add_argument("--wind-teacher", type=Path, required=True)
    p.add_argument("--flight-teacher", type=Path, default=None,
                   help="the gravity answer for items whose Earth motion (E's x̂₀) has a flight (default: G's for all)")
    p.add_argument("--min-flight-s", type=float, default=0.1)
    p.add_argument("--earth-teacher", type=Path, default=None, help="the Earth answer (default: the gravity teacher)")
    p.add_argument("--backbone", type=Path, required=True)
    p.add_argument("--out", type=Path, required=True)
    p.add_argument("--data", type=Path, nargs="+", required=True)
    p.add_argument("--steps", type=int, default=400)
    p.add_argument("--batch-size", type=int, default=64)
    p.add_argument("--lr", type=float, default=1e-4)
    p.add_argument("--ema-decay", type=float, default=0.99)
    p.add_argument("--seed", type=int, default=61)
    p.add_argument("--gravity-gain", type=float, default=1.0)
    p.add_argument("--alphas", type=float, nargs="*", default=[], help="adapter strengths drawn per item (default: 1, as in training)")
    p.add_argument("--pairs", type=float, default=10.0, help="weight of the answer term (student vs target φ-minus-Earth difference)")
    p.add_argument("--drift", type=float, default=20.0, help="weight of the mean root-velocity answer term on windy items")
    p.add_argument("--text-table", type=Path, default=Path(".gpu/captions.safetensors"))
    a = p.parse_args()
    config = RunConfig()
    init = read_config(a.backbone)
    config.model.backbone, config.model.text_encoder = init.backbone, init.text_encoder
    config.model.sim = read_config(a.student_init).sim
    tc = config.train
    tc.mode, tc.steps, tc.batch_size, tc.seed = "adapters", a.steps, a.batch_size, a.seed
    tc.ema, tc.ema_decay, tc.save_every, tc.log_every = True, a.ema_decay, 100, 25
    tc.optim.lr = a.lr
    tc.crop.max_frames, tc.crop.trim_padding = 120, True
    tc.env_pairs = 0.0
    dataset = open_training_dataset(list(a.data), "first_try", tc.seed, targets="source-anchored")
    encoder = open_caption_table(a.text_table, config.model.text_encoder, "cpu")
    trainer = DistillTrainer(a.out, config, dataset, text_encoder=encoder, device="cpu", init_model=a.backbone,
                             init_adapters=a.student_init, gravity_teacher=a.gravity_teacher,
                             wind_teacher=a.wind_teacher, earth_teacher=a.earth_teacher,
                             flight_teacher=a.flight_teacher, min_flight_s=a.min_flight_s,
                             gravity_gain=a.gravity_gain,
                             pairs=a.pairs, drift=a.drift, alphas=a.alphas)
    losses = trainer.train(progress=False)
    if trainer.flying:
        fly, low = map(sum, zip(*trainer.flying))
        print(f"low-gravity items whose Earth motion flies (F's answer): {fly} of {low}")
    tail = losses[-25:]
    print(f"distilled to step {trainer.step}; last-25 loss {sum(tail) / max(1, len(tail)):.5f}; model {a.out / 'model'}")


if __name__ == "__main__":
    main()
