"""The paired φ-difference loss (``train.env_pairs``): twins, aligned batches, shared noise, the loss, training."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
import torch

from simdiff.data.augment import AugmentConfig, AugmentedHumanML3D, augment
from simdiff.errors import SimdiffError
from simdiff.eval.testing import write_tiny_corpus
from simdiff.model import Condition, load_pretrained
from simdiff.train import Trainer, synthetic_dataset
from simdiff.data.batch import collate
from simdiff.train.data import StepBatcher, StepBatches
from simdiff.train.geometric import CropConfig, crop_batch
from simdiff.train.testing import HashTextEncoder as HashText
from simdiff.train.testing import tiny_run_config as run_config


class StretchProjector:
    """Rollout = reference with heights stretched by 2 % per unit of |φ − Earth|₁ (m/s², N); every pair is kept."""

    def __call__(self, motions: Any, envs: Any) -> Any:
        for m, e in zip(motions, envs):
            g, wx, wy = e.as_tuple()
            stretch = 1.0 + 0.02 * (abs(g + 9.81) + abs(wx) + abs(wy))
            yield np.asarray(m, dtype=np.float32) * np.array([1.0, stretch, 1.0], dtype=np.float32), {
                "success": True, "d_l2_pose": 0.5, "d_l2": 0.5, "residual": {"force_mean_n": 1.0, "force_mean_mg": 0.01},
                "cpu_s": 0.0}


@pytest.fixture(scope="module")
def paired_corpus(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("pairs")
    corpus = write_tiny_corpus(root / "c", n_train=3, n_test=1, frames=64)
    out = root / "aug"
    augment(corpus, out, AugmentConfig(mode="paired", conditions=3, seed=2), projector=StretchProjector(),
            progress=False)
    return out


def test_crop_gives_twins_one_window() -> None:
    base = np.arange(50 * 263, dtype=np.float32).reshape(50, 263) / 1000.0
    short = np.zeros_like(base)
    short[:30] = base[:30]
    items = [{"motion": base, "length": 50, "caption": "a"}, {"motion": short, "length": 30, "caption": "b"},
             {"motion": base + 1.0, "length": 50, "caption": "a"}, {"motion": short + 1.0, "length": 30, "caption": "b"}]
    for seed in range(5):
        batch = crop_batch(collate(items), CropConfig(max_frames=20), np.random.default_rng(seed), pairs=2)
        assert batch["motion"].shape == (4, 20, 263)
        assert torch.allclose(batch["motion"][2] - batch["motion"][0], torch.ones(20, 263))
        assert torch.allclose(batch["motion"][3] - batch["motion"][1], torch.ones(20, 263))
    # unpaired crops draw one offset per long clip, as before
    a, b = np.random.default_rng(7), np.random.default_rng(7)
    crop_batch(collate(items), CropConfig(max_frames=20), a)
    [b.integers(31) for _ in range(2)], [b.integers(11) for _ in range(2)]
    assert a.integers(1 << 30) == b.integers(1 << 30)


def test_twins_are_the_same_source_clip_under_another_phi(paired_corpus: Path) -> None:
    ds = AugmentedHumanML3D(paired_corpus)
    envs = {it.clip_id: ds.env_table[it.clip_id] for it in ds.sim.items}
    rng = np.random.default_rng(0)
    seen_earth_anchor = False
    for i, item in enumerate(ds.sim.items):
        j = ds.twin(i, rng)
        assert j is not None and j != i
        mine, theirs = envs[item.clip_id], envs[ds.sim.items[j].clip_id]
        assert mine["source"] == theirs["source"]
        if mine["factor"] == "earth":
            seen_earth_anchor = True
            assert theirs["factor"] != "earth"
        else:
            assert theirs["env"] == [-9.81, 0.0, 0.0]  # the Earth twin when there is one
    assert seen_earth_anchor
    assert ds.twin(len(ds.sim), rng) is None  # out of the simulated part: no twin


def test_paired_batches_align_twins(paired_corpus: Path) -> None:
    ds = AugmentedHumanML3D(paired_corpus)
    batcher = StepBatcher(len(ds), 6, seed=3)
    batches = StepBatches(ds, batcher, 3, 0, CropConfig(max_frames=24, trim_padding=True), pairs=True)
    full = lambda i: torch.as_tensor(ds.normalizer.normalize(ds.sim.load_motion(ds.sim.items[i])))  # noqa: E731
    for step in range(4):
        b = batches.batch(step)
        assert b["paired"].tolist() == [True] * 3 and b["motion"].shape[0] == 6
        assert b["captions"][:3] == b["captions"][3:]
        assert torch.equal(b["lengths"][:3], b["lengths"][3:])
        for j, index in enumerate(batcher.indices(step)[:3]):
            twin = ds.twin(index, np.random.default_rng([3, step, 0, j, 1]))
            a, t, n = full(index), full(twin), int(b["lengths"][j])
            assert not torch.allclose(a, t, atol=1e-3)  # the twins differ ...
            starts = [o for o in range(len(a) - n + 1) if torch.allclose(a[o:o + n], b["motion"][j, :n], atol=1e-5)]
            assert starts  # ... and the twin's window is the anchor's (the tiny clips are periodic: any match)
            assert torch.allclose(t[starts[0]:starts[0] + n], b["motion"][j + 3, :n], atol=1e-5)
    assert torch.equal(batches.batch(2)["motion"], batches.batch(2)["motion"])  # deterministic per step
    with pytest.raises(SimdiffError, match="even batch"):
        StepBatches(ds, StepBatcher(len(ds), 5, seed=3), 3, 0, CropConfig(), pairs=True)
    with pytest.raises(SimdiffError, match="twins"):
        StepBatches(synthetic_dataset(4, 20, max_frames=20, with_env=True), StepBatcher(4, 4, 1), 1, 0, CropConfig(),
                    pairs=True)


def test_pair_loss_counts_paired_rows_only() -> None:
    x0 = torch.zeros(4, 3, 2)
    x0[0] = 1.0  # anchor 0 differs from its twin (row 2) by 1
    mask = torch.ones(4, 3, dtype=torch.bool)
    pred = x0.clone()
    assert float(Trainer._pair_loss(pred, x0, mask, torch.tensor([True, True]))) == 0.0
    pred[0] = 0.0  # predicts no response
    assert float(Trainer._pair_loss(pred, x0, mask, torch.tensor([True, False]))) == pytest.approx(1.0)
    assert float(Trainer._pair_loss(pred, x0, mask, torch.tensor([True, True]))) == pytest.approx(0.5)
    assert float(Trainer._pair_loss(pred, x0, mask, torch.tensor([False, False]))) == 0.0


def _backbone(tmp_path: Path) -> Path:
    ds = synthetic_dataset(4, 20, max_frames=20)
    Trainer(tmp_path / "bb", run_config(2), ds, text_encoder=HashText()).train(progress=False)
    return tmp_path / "bb" / "model"


def test_trainer_validates_env_pairs(tmp_path: Path, paired_corpus: Path) -> None:
    ds = synthetic_dataset(4, 20, max_frames=20)
    with pytest.raises(SimdiffError, match="adapters mode"):
        Trainer(tmp_path / "x", run_config(2, env_pairs=1.0), ds, text_encoder=HashText())
    bb = _backbone(tmp_path)
    with pytest.raises(SimdiffError, match="env_pairs"):
        Trainer(tmp_path / "y", run_config(2, mode="adapters", sim=True, env_pairs=-1.0), ds, text_encoder=HashText(),
                init_model=bb)
    trainer = Trainer(tmp_path / "z", run_config(2, mode="adapters", sim=True, env_pairs=1.0),
                      synthetic_dataset(4, 20, max_frames=20, with_env=True), text_encoder=HashText(), init_model=bb)
    with pytest.raises(SimdiffError, match="twins"):
        trainer.train(progress=False)


class ShiftTwins:
    """Synthetic twins: clip c under φ = (g, w_x, 0), w_x ∈ {0, ±10}; x = base_c + 0.5·w_x/10 in every feature."""

    def __init__(self, clips: int = 4, frames: int = 20) -> None:
        rng = np.random.default_rng(0)
        self.base = [rng.normal(size=(frames, 263)).astype(np.float32) * 0.3 for _ in range(clips)]
        self.winds = (0.0, -10.0, 10.0)
        self.frames = frames

    def __len__(self) -> int:
        return len(self.base) * len(self.winds)

    def get(self, index: int, rng: np.random.Generator | None = None) -> dict[str, Any]:
        clip, k = divmod(index, len(self.winds))
        w = self.winds[k]
        return {"motion": self.base[clip] + 0.05 * w, "length": self.frames, "caption": f"clip {clip}",
                "env": np.array([-9.81, w, 0.0], dtype=np.float32)}

    def __getitem__(self, index: int) -> dict[str, Any]:
        return self.get(index)

    def twin(self, index: int, rng: np.random.Generator) -> int | None:
        clip, k = divmod(index, len(self.winds))
        return clip * len(self.winds) + (0 if k else int(rng.integers(1, len(self.winds))))


def _response(model_dir: Path, ds: ShiftTwins) -> float:
    """Mean predicted x̂₀(w_x = +10) − x̂₀(Earth) at moderate noise, same x_t (the truth is 0.5)."""
    net, _, _ = load_pretrained(model_dir, "cpu")
    net.eval()
    text = HashText().encode([f"clip {c}" for c in range(len(ds.base))])
    x = torch.as_tensor(np.stack(ds.base)) + 0.25
    t = torch.full((len(ds.base),), 100)
    env = lambda w: torch.tensor([[-9.81, w, 0.0]]).repeat(len(ds.base), 1)  # noqa: E731
    with torch.no_grad():
        hi = net(x, t, Condition(text=text, env=env(10.0), alpha=1.0))
        lo = net(x, t, Condition(text=text, env=env(0.0), alpha=1.0))
    return float((hi - lo).mean())


def test_paired_training_learns_a_response_to_phi_and_resumes_exactly(tmp_path: Path) -> None:
    bb = _backbone(tmp_path)
    ds = ShiftTwins()
    responses = {}
    for name, weight in (("pairs", 10.0),):
        cfg = run_config(40, mode="adapters", sim=True, env_pairs=weight, batch_size=6, seed=4)
        trainer = Trainer(tmp_path / name, cfg, ds, text_encoder=HashText(), init_model=bb)
        before = {k: v.clone() for k, v in trainer.network.state_dict().items() if k.startswith("backbone.")}
        trainer.train(progress=False)
        after = trainer.network.state_dict()
        assert all(torch.equal(after[k], v) for k, v in before.items())  # the backbone stays frozen
        responses[name] = _response(tmp_path / name / "model", ds)
    # after training, φ alone (same x_t) moves the prediction the right way (the truth is +0.5; 40 tiny steps learn a
    # part of it; whether pairs learn it faster than the plain loss is a question for a full training run)
    assert 0.04 < responses["pairs"] < 0.6, responses
    # a paired run stopped at a checkpoint and resumed ends bit-identical
    cfg = run_config(6, mode="adapters", sim=True, env_pairs=10.0, batch_size=6, seed=4, save_every=3)
    Trainer(tmp_path / "full", cfg, ds, text_encoder=HashText(), init_model=bb).train(progress=False)
    Trainer(tmp_path / "cut", cfg, ds, text_encoder=HashText(), init_model=bb).train(until=3, progress=False)
    Trainer(tmp_path / "cut", cfg, ds, text_encoder=HashText()).train(progress=False)
    full, _, _ = load_pretrained(tmp_path / "full" / "model", "cpu")
    cut, _, _ = load_pretrained(tmp_path / "cut" / "model", "cpu")
    for (k, a), b in zip(full.state_dict().items(), cut.state_dict().values()):
        assert torch.equal(a, b), k


def test_pipeline_adapters_stage_hashes_env_pairs_only_when_on(tmp_path: Path) -> None:
    from simdiff.train.pipeline.config import budget_config
    from simdiff.train.pipeline.context import PipelineContext
    from simdiff.train.pipeline.stages import adapters_settings

    ctx = PipelineContext(out=tmp_path, config=budget_config("quick"), progress=False)
    off = adapters_settings(ctx)
    assert "env_pairs" not in off  # the same hash as before the setting existed: older runs stay current
    ctx.config.adapters.env_pairs = 10.0
    assert adapters_settings(ctx) == {**off, "env_pairs": 10.0}


def test_twin_drift_mse_compares_mean_root_velocity_differences() -> None:
    from simdiff.diffusion.losses import twin_drift_mse

    g = torch.Generator().manual_seed(0)
    x0 = torch.randn(4, 10, 263, generator=g)  # twins: items 0,1 and 2,3
    mask = torch.ones(4, 10, dtype=torch.bool)
    paired = torch.tensor([True, True])
    assert float(twin_drift_mse(x0, x0, mask, paired)) == 0.0
    noisy = x0.clone()
    wiggle = torch.randn(2, 10, 2, generator=g)
    noisy[:2, :, 1:3] += wiggle - wiggle.mean(dim=1, keepdim=True)  # per-frame change, same window means
    noisy[:, :, 3:] += 1.0  # other channels do not count
    assert float(twin_drift_mse(noisy, x0, mask, paired)) < 1e-10
    drift = x0.clone()
    drift[2:, :, 1] -= 0.3  # the twin drifts 0.3 less along x: the true mean difference grows by 0.3 on one channel
    assert abs(float(twin_drift_mse(x0, drift, mask, paired)) - 0.3**2 / 2) < 1e-6
    short = mask.clone()
    short[0, 5:] = False  # only the frames valid in both twins are averaged
    only_late = x0.clone()
    only_late[0, 5:, 1] += 9.0
    assert float(twin_drift_mse(only_late, x0, short, torch.tensor([True, False]))) < 1e-10
    assert float(twin_drift_mse(drift, x0, mask, torch.tensor([False, False]))) == 0.0


def test_trainer_validates_env_pairs_drift(tmp_path: Path) -> None:
    ds = synthetic_dataset(4, 20, max_frames=20, with_env=True)
    bb = _backbone(tmp_path)
    with pytest.raises(SimdiffError, match="env_pairs_drift = 1.0 needs env_pairs > 0"):
        Trainer(tmp_path / "a", run_config(2, mode="adapters", sim=True, env_pairs_drift=1.0), ds,
                text_encoder=HashText(), init_model=bb)
    with pytest.raises(SimdiffError, match="env_pairs_drift must be a finite weight >= 0, got -1.0"):
        Trainer(tmp_path / "b", run_config(2, mode="adapters", sim=True, env_pairs=1.0, env_pairs_drift=-1.0), ds,
                text_encoder=HashText(), init_model=bb)


def test_drift_term_trains_and_changes_the_run(tmp_path: Path) -> None:
    bb = _backbone(tmp_path)
    ds = ShiftTwins()
    losses = {}
    for name, mu in (("pairs", 0.0), ("drift", 100.0)):
        cfg = run_config(6, mode="adapters", sim=True, env_pairs=10.0, env_pairs_drift=mu, batch_size=6, seed=4)
        trainer = Trainer(tmp_path / name, cfg, ds, text_encoder=HashText(), init_model=bb)
        losses[name] = trainer.train(progress=False)
    assert all(np.isfinite(losses["drift"]))
    assert losses["drift"][0] > losses["pairs"][0]  # the same first batch, one more non-negative term


class GravityTwins(ShiftTwins):
    """ShiftTwins whose φ differ in gravity only: (−9.81 + g_k, 0, 0) with the same shifted motions."""

    def get(self, index: int, rng: np.random.Generator | None = None) -> dict[str, Any]:
        item = super().get(index, rng)
        item["env"] = np.array([-9.81 + abs(float(item["env"][1])) / 2.0, 0.0, 0.0], dtype=np.float32)
        return item


def test_pair_twins_wind_leaves_gravity_twins_out_of_the_paired_loss(tmp_path: Path) -> None:
    bb = _backbone(tmp_path)
    losses = {}
    for ds_name, ds in (("gravity", GravityTwins()), ("wind", ShiftTwins())):
        for name, lam, which in (("all", 10.0, "all"), ("wind", 10.0, "wind"), ("wind_big", 1000.0, "wind")):
            cfg = run_config(2, mode="adapters", sim=True, env_pairs=lam, pair_twins=which, batch_size=6, seed=4)
            trainer = Trainer(tmp_path / f"p_{ds_name}_{name}", cfg, ds, text_encoder=HashText(), init_model=bb)
            losses[ds_name, name] = trainer.train(progress=False)
    assert losses["gravity", "all"][0] > losses["gravity", "wind"][0]  # gravity twins' difference counts under "all"
    assert losses["gravity", "wind"] == losses["gravity", "wind_big"]  # ... and not at all under "wind"
    assert losses["wind", "wind"] == losses["wind", "all"]  # wind twins are in it either way
    assert losses["wind", "wind_big"][0] > losses["wind", "wind"][0]
    with pytest.raises(SimdiffError, match="pair_twins must be 'all' or 'wind', got 'gusts'"):
        Trainer(tmp_path / "bad_p", run_config(2, mode="adapters", sim=True, env_pairs=1.0, pair_twins="gusts"),
                ShiftTwins(), text_encoder=HashText(), init_model=bb)


def test_drift_pairs_wind_leaves_gravity_twins_out_of_the_drift_term(tmp_path: Path) -> None:
    bb = _backbone(tmp_path)
    losses = {}
    for ds_name, ds in (("gravity", GravityTwins()), ("wind", ShiftTwins())):
        for name, mu, which in (("off", 0.0, "all"), ("all", 100.0, "all"), ("wind", 100.0, "wind")):
            cfg = run_config(2, mode="adapters", sim=True, env_pairs=10.0, env_pairs_drift=mu, drift_pairs=which,
                             batch_size=6, seed=4)
            trainer = Trainer(tmp_path / f"{ds_name}_{name}", cfg, ds, text_encoder=HashText(), init_model=bb)
            losses[ds_name, name] = trainer.train(progress=False)
    assert losses["gravity", "all"][0] > losses["gravity", "off"][0]  # gravity twins drift apart: the term counts them
    assert losses["gravity", "wind"] == losses["gravity", "off"]  # ... but not under drift_pairs "wind"
    assert losses["wind", "wind"] == losses["wind", "all"]  # wind twins are in it either way
    with pytest.raises(SimdiffError, match="drift_pairs must be 'all' or 'wind', got 'gusts'"):
        Trainer(tmp_path / "bad", run_config(2, mode="adapters", sim=True, env_pairs=1.0, drift_pairs="gusts"),
                ShiftTwins(), text_encoder=HashText(), init_model=bb)


def test_cross_twins_noise_each_twin_from_the_other(tmp_path: Path) -> None:
    bb = _backbone(tmp_path)
    seen: list[torch.Tensor] = []
    x0 = torch.randn(6, 8, 263, generator=torch.Generator().manual_seed(1))
    paired = torch.tensor([True, True, False])
    for p in (0.0, 1.0):
        cfg = run_config(2, mode="adapters", sim=True, env_pairs=1.0, cross_twins=p, batch_size=6, seed=4)
        trainer = Trainer(tmp_path / f"x{p}", cfg, ShiftTwins(), text_encoder=HashText(), init_model=bb)
        trainer.model = lambda x, t, c: seen.append(x) or x  # type: ignore[assignment]
        trainer._paired_prediction(x0, None, torch.Generator().manual_seed(0), paired)  # type: ignore[arg-type]
    g = torch.Generator().manual_seed(0)
    t = torch.randint(0, trainer.scheduler.num_train_timesteps, (3,), generator=g).repeat(2)
    noise = torch.randn((3, 8, 263), generator=g).repeat(2, 1, 1)
    own = trainer.scheduler.add_noise(x0, noise, t)
    crossed = trainer.scheduler.add_noise(torch.cat([x0[3:], x0[:3]]), noise, t)
    assert torch.equal(seen[0], own)  # p 0: each twin from its own motion, as before
    for row, source in ((0, crossed), (1, crossed), (2, own), (3, crossed), (4, crossed), (5, own)):
        assert torch.equal(seen[1][row], source[row]), row  # p 1: paired twins swapped, the unpaired row kept


def test_cross_match_crosses_only_the_pairs_whose_caption_matches(tmp_path: Path) -> None:
    bb = _backbone(tmp_path)
    seen: list[torch.Tensor] = []
    x0 = torch.randn(6, 8, 263, generator=torch.Generator().manual_seed(1))
    paired = torch.tensor([True, True, True])
    captions = ["a person JUMPS up", "a person walks", "someone hops", "a person JUMPS up", "a person walks",
                "someone hops"]
    for match in ("", "jump|hop"):
        cfg = run_config(2, mode="adapters", sim=True, env_pairs=1.0, cross_twins=1.0, cross_match=match,
                         batch_size=6, seed=4)
        trainer = Trainer(tmp_path / f"m{len(match)}", cfg, ShiftTwins(), text_encoder=HashText(), init_model=bb)
        trainer.model = lambda x, t, c: seen.append(x) or x  # type: ignore[assignment]
        trainer._paired_prediction(x0, None, torch.Generator().manual_seed(0), paired,  # type: ignore[arg-type]
                                   captions)
    g = torch.Generator().manual_seed(0)
    t = torch.randint(0, trainer.scheduler.num_train_timesteps, (3,), generator=g).repeat(2)
    noise = torch.randn((3, 8, 263), generator=g).repeat(2, 1, 1)
    own = trainer.scheduler.add_noise(x0, noise, t)
    crossed = trainer.scheduler.add_noise(torch.cat([x0[3:], x0[:3]]), noise, t)
    assert torch.equal(seen[0], crossed)  # no pattern: every pair crossed at p 1
    for row, source in ((0, crossed), (1, own), (2, crossed), (3, crossed), (4, own), (5, crossed)):
        assert torch.equal(seen[1][row], source[row]), row  # the walk pair keeps its own x_t
    with pytest.raises(SimdiffError, match=r"cross_match 'jump\(' is not a regular expression"):
        Trainer(tmp_path / "bad", run_config(2, mode="adapters", sim=True, env_pairs=1.0, cross_twins=0.5,
                                             cross_match="jump("), ShiftTwins(), text_encoder=HashText(), init_model=bb)
    with pytest.raises(SimdiffError, match="cross_match 'jump' needs cross_twins > 0"):
        Trainer(tmp_path / "bad2", run_config(2, mode="adapters", sim=True, env_pairs=1.0, cross_match="jump"),
                ShiftTwins(), text_encoder=HashText(), init_model=bb)
    cfg = run_config(2, mode="adapters", sim=True, env_pairs=1.0, cross_twins=0.5, cross_match="clip 1",
                     batch_size=6, seed=4)
    losses = Trainer(tmp_path / "train", cfg, ShiftTwins(), text_encoder=HashText(), init_model=bb).train(progress=False)
    assert all(np.isfinite(losses))


def test_cross_twins_train_and_are_checked(tmp_path: Path) -> None:
    bb = _backbone(tmp_path)
    losses = {}
    for p in (0.0, 0.5):
        cfg = run_config(2, mode="adapters", sim=True, env_pairs=1.0, cross_twins=p, batch_size=6, seed=4)
        losses[p] = Trainer(tmp_path / f"c{p}", cfg, ShiftTwins(), text_encoder=HashText(),
                            init_model=bb).train(progress=False)
    assert all(np.isfinite(losses[0.5])) and losses[0.5] != losses[0.0]
    for bad, match in ((1.5, r"cross_twins must be a share in \[0, 1\], got 1.5"),
                       (-0.1, r"cross_twins must be a share in \[0, 1\], got -0.1")):
        with pytest.raises(SimdiffError, match=match):
            Trainer(tmp_path / "bad", run_config(2, mode="adapters", sim=True, env_pairs=1.0, cross_twins=bad),
                    ShiftTwins(), text_encoder=HashText(), init_model=bb)
    with pytest.raises(SimdiffError, match="cross_twins = 0.5 needs env_pairs > 0"):
        Trainer(tmp_path / "bad2", run_config(2, mode="adapters", sim=True, cross_twins=0.5), ShiftTwins(),
                text_encoder=HashText(), init_model=bb)
