"""Trainer: loss falls, checkpoints are atomic and resumable bit-exactly, adapters train alone."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
import torch
from safetensors.torch import load_file

from simdiff.errors import SimdiffError
from simdiff.model import Condition, load_pretrained
from simdiff.inference.generator import MotionGenerator
from simdiff.train import StepBatcher, Trainer, synthetic_dataset
from simdiff.train.config import OptimConfig, lr_at
from simdiff.train.testing import HashTextEncoder as HashText
from simdiff.train.testing import tiny_run_config as run_config
from simdiff.train.state import latest_checkpoint


pytestmark = pytest.mark.usefixtures("one_torch_thread")



def test_step_batcher_is_a_seeded_epoch_permutation() -> None:
    b = StepBatcher(10, 4, seed=1)
    first = [i for s in range(5) for i in b.indices(s)]
    assert sorted(first[:10]) == list(range(10)) and sorted(first[10:20]) == list(range(10))
    r0, r1 = StepBatcher(10, 4, 1, world_size=2, rank=0), StepBatcher(10, 4, 1, world_size=2, rank=1)
    assert r0.indices(3) + r1.indices(3) == b.indices(3)
    with pytest.raises(SimdiffError):
        StepBatcher(10, 3, 1, world_size=2)


def test_loss_falls_and_outputs_written(tmp_path) -> None:
    ds = synthetic_dataset(4, 30, max_frames=30)
    trainer = Trainer(tmp_path, run_config(60, save_every=25, dropout=0.0), ds, text_encoder=HashText())
    losses = trainer.train(progress=False)
    assert len(losses) == 60 and sum(losses[-10:]) < 0.8 * sum(losses[:10])
    assert sorted(p.name for p in (tmp_path / "model").iterdir()) == ["config.json", "model.safetensors"]
    assert latest_checkpoint(tmp_path).name == "step_000000060"
    steps = sorted(p.name for p in (tmp_path / "checkpoints").glob("step_*"))
    assert steps == ["step_000000050", "step_000000060"]  # keep_checkpoints = 2
    assert not list((tmp_path / "checkpoints").glob(".tmp*"))
    assert json.loads((tmp_path / "train_config.json").read_text())["train"]["steps"] == 60


def _weights(folder: Path) -> dict[str, torch.Tensor]:
    return load_file(str(folder / "model.safetensors"))


class Interrupt(Exception):
    pass


@pytest.mark.parametrize(("ema", "schedule"), [(False, "constant"), (True, "constant"), (True, "cosine")])
def test_resume_after_interruption_is_bit_exact(tmp_path, ema: bool, schedule: str) -> None:
    ds = synthetic_dataset(6, 24, max_frames=24)
    cfg = run_config(10, save_every=4, ema=ema, ema_decay=0.9)
    cfg.train.optim.lr_schedule = schedule
    Trainer(tmp_path / "a", cfg, ds, text_encoder=HashText()).train(progress=False)

    def crash(step: int, loss: float) -> None:
        if step == 6:
            raise Interrupt

    with pytest.raises(Interrupt):
        Trainer(tmp_path / "b", cfg, ds, text_encoder=HashText()).train(progress=False, on_step=crash)
    assert latest_checkpoint(tmp_path / "b").name == "step_000000004"
    resumed = Trainer(tmp_path / "b", cfg, ds, text_encoder=HashText())
    assert resumed.step == 4
    resumed.train(progress=False)
    for sub in ("model", "checkpoints/step_000000010"):
        a, b = _weights(tmp_path / "a" / sub), _weights(tmp_path / "b" / sub)
        assert a.keys() == b.keys() and all(torch.equal(a[k], b[k]) for k in a), sub
    sa = load_file(str(tmp_path / "a/checkpoints/step_000000010/state.safetensors"))
    sb = load_file(str(tmp_path / "b/checkpoints/step_000000010/state.safetensors"))
    assert sa.keys() == sb.keys() and all(torch.equal(sa[k], sb[k]) for k in sa)
    assert any(k.startswith("ema.") for k in sa) == ema


def test_lr_at_follows_the_named_schedule() -> None:
    o = OptimConfig(lr=2e-4)
    assert [lr_at(o, s, 10) for s in (0, 5, 10)] == [2e-4] * 3
    o.lr_schedule = "cosine"
    assert lr_at(o, 0, 10) == pytest.approx(2e-4) and lr_at(o, 5, 10) == pytest.approx(1e-4)
    assert lr_at(o, 10, 10) == pytest.approx(0.0, abs=1e-12) and lr_at(o, 2, 10) > lr_at(o, 3, 10)


def test_cosine_schedule_sets_each_steps_lr_and_a_bad_name_is_refused(tmp_path) -> None:
    ds = synthetic_dataset(4, 24, max_frames=24)
    cfg = run_config(8, save_every=0)
    cfg.train.optim.lr_schedule = "cosine"
    trainer = Trainer(tmp_path / "a", cfg, ds, text_encoder=HashText())
    seen: list[float] = []
    trainer.train(progress=False, on_step=lambda step, loss: seen.append(trainer.optimizer.param_groups[0]["lr"]))
    assert seen == pytest.approx([lr_at(cfg.train.optim, s, 8) for s in range(8)])
    cfg.train.optim.lr_schedule = "linear"
    with pytest.raises(SimdiffError, match="'linear'"):
        Trainer(tmp_path / "b", cfg, ds, text_encoder=HashText())


def test_ema_export_differs_from_raw(tmp_path) -> None:
    ds = synthetic_dataset(4, 20, max_frames=20)
    trainer = Trainer(tmp_path, run_config(5, ema=True, ema_decay=0.5), ds, text_encoder=HashText())
    trainer.train(progress=False)
    exported = _weights(tmp_path / "model")
    raw = trainer.network.state_dict()
    name = "embed_text.weight"
    assert not torch.equal(exported[name], raw[name])
    assert torch.equal(exported[name], trainer.ema.shadow[name])


def test_adapter_training_freezes_the_backbone(tmp_path) -> None:
    ds = synthetic_dataset(4, 20, max_frames=20)
    Trainer(tmp_path / "bb", run_config(3), ds, text_encoder=HashText()).train(progress=False)
    backbone, _, _ = load_pretrained(tmp_path / "bb" / "model")
    env_ds = synthetic_dataset(4, 20, max_frames=20, with_env=True)
    cfg = run_config(4, mode="adapters", sim=True)
    trainer = Trainer(tmp_path / "ad", cfg, env_ds, text_encoder=HashText(), init_model=tmp_path / "bb" / "model")
    assert set(trainer.trainable) == {n for n, _ in trainer.network.named_parameters()
                                      if n.startswith(("sim_encoder.", "adapters."))}
    before = {k: v.clone() for k, v in trainer.network.state_dict().items()}
    trainer.train(progress=False)
    after = trainer.network.state_dict()
    for key, value in before.items():
        if key.startswith("backbone."):
            assert torch.equal(after[key], value), key  # bit-identical
            assert torch.equal(after[key], backbone.state_dict()[key[len("backbone."):]])
    assert not torch.equal(after["adapters.0.up.weight"], before["adapters.0.up.weight"])
    assert not torch.equal(after["sim_encoder.proj.weight"], before["sim_encoder.proj.weight"])
    # With α = 0 the trained SimDiff equals the backbone exactly.
    net = trainer.network.eval()
    x, t = torch.randn(2, 20, 263), torch.tensor([3, 700])
    c = Condition(text=torch.randn(2, 384), env=torch.tensor([[-3.0, 5.0, 0.0], [-15.0, 0.0, -8.0]]), alpha=0.0)
    with torch.no_grad():
        assert torch.equal(net(x, t, c), backbone.eval()(x, t, Condition(text=c.text)))
        c.alpha = 1.0
        assert not torch.allclose(net(x, t, c), backbone(x, t, Condition(text=c.text)))
    gen = MotionGenerator.load(tmp_path / "ad" / "model", load_text=False)
    assert gen.is_simdiff


def test_adapter_training_needs_env_and_backbone(tmp_path) -> None:
    ds = synthetic_dataset(4, 20, max_frames=20)
    with pytest.raises(SimdiffError, match="backbone checkpoint"):
        Trainer(tmp_path / "x", run_config(2, mode="adapters", sim=True), ds, text_encoder=HashText())
    Trainer(tmp_path / "bb", run_config(1), ds, text_encoder=HashText()).train(progress=False)
    trainer = Trainer(tmp_path / "ad", run_config(2, mode="adapters", sim=True), ds, text_encoder=HashText(),
                      init_model=tmp_path / "bb" / "model")
    with pytest.raises(SimdiffError, match="'env'"):
        trainer.train(progress=False)


def test_categorical_env_index(tmp_path) -> None:
    from simdiff.train import TensorMotionDataset

    base = synthetic_dataset(4, 20, max_frames=20)
    ds = TensorMotionDataset([m[:20] for m in base.motions], base.captions, env_indices=[0, 1, 2, 3], max_frames=20)
    Trainer(tmp_path / "bb", run_config(1), ds, text_encoder=HashText()).train(progress=False)
    cfg = run_config(2, mode="adapters", sim=True)
    cfg.model.sim.mode = "categorical"
    cfg.model.sim.num_categories = 4
    losses = Trainer(tmp_path / "ad", cfg, ds, text_encoder=HashText(), init_model=tmp_path / "bb" / "model").train(progress=False)
    assert len(losses) == 2


def test_ema_warms_up_so_initial_weights_fade() -> None:
    import torch
    from torch import nn

    from simdiff.train.ema import EMA

    p = nn.Parameter(torch.zeros(3))
    ema = EMA({"p": p}, decay=0.999)
    assert ema.decay_at(0) == pytest.approx(0.1) and ema.decay_at(None) == 0.999 and ema.decay_at(10**6) == 0.999
    with torch.no_grad():
        p.fill_(1.0)
    for step in range(1000):
        ema.update(step)
    # without warm-up the initial zeros would still weigh 0.999**1000 = 0.37
    assert float(ema.shadow["p"][0]) > 0.99


def test_loader_workers_give_the_same_run_as_in_process_batches(tmp_path) -> None:
    ds = synthetic_dataset(6, 24, max_frames=24)
    cfg = run_config(6, save_every=3)
    Trainer(tmp_path / "a", cfg, ds, text_encoder=HashText()).train(progress=False)
    Trainer(tmp_path / "b", cfg, ds, text_encoder=HashText(), loader_workers=2).train(progress=False)
    a, b = _weights(tmp_path / "a" / "model"), _weights(tmp_path / "b" / "model")
    assert a.keys() == b.keys() and all(torch.equal(a[k], b[k]) for k in a)
    with pytest.raises(SimdiffError, match="loader_workers must be >= 0, got -1"):
        Trainer(tmp_path / "c", cfg, ds, text_encoder=HashText(), loader_workers=-1)


def test_train_for_stops_at_the_first_checkpoint_past_the_wall_clock_cap(tmp_path) -> None:
    ds = synthetic_dataset(4, 20, max_frames=20)
    trainer = Trainer(tmp_path, run_config(9, save_every=3), ds, text_encoder=HashText())
    assert len(trainer.train_for(1e-9, progress=False)) == 3  # one checkpoint period, then the cap holds
    assert trainer.step == 3 and latest_checkpoint(tmp_path).name == "step_000000003"
    trainer.train_for(0.0, progress=False)  # no cap: to the configured steps
    assert trainer.step == 9


def test_backbone_warm_start_begins_from_the_init_weights(tmp_path) -> None:
    """``init_model`` in backbone mode: step 0 holds the init's weights (a SimDiff folder gives its backbone), the
    optimiser starts fresh, and a run folder with a checkpoint resumes it instead."""
    ds = synthetic_dataset(4, 20, max_frames=20)
    Trainer(tmp_path / "bb", run_config(3), ds, text_encoder=HashText()).train(progress=False)
    start, _, _ = load_pretrained(tmp_path / "bb" / "model")
    warm = Trainer(tmp_path / "warm", run_config(2, seed=5), ds, text_encoder=HashText(),
                   init_model=tmp_path / "bb" / "model")
    assert warm.step == 0 and not warm.optimizer.state
    assert all(torch.equal(v, start.state_dict()[k]) for k, v in warm.network.state_dict().items())
    cold = Trainer(tmp_path / "cold", run_config(2, seed=5), ds, text_encoder=HashText())
    assert not all(torch.equal(v, start.state_dict()[k]) for k, v in cold.network.state_dict().items())
    warm.train(progress=False)
    resumed = Trainer(tmp_path / "warm", run_config(4, seed=5), ds, text_encoder=HashText(),
                      init_model=tmp_path / "bb" / "model")
    assert resumed.step == 2
    assert all(torch.equal(v, warm.network.state_dict()[k]) for k, v in resumed.network.state_dict().items())
    # A SimDiff folder gives its backbone; a different architecture is refused in one line.
    env_ds = synthetic_dataset(4, 20, max_frames=20, with_env=True)
    Trainer(tmp_path / "ad", run_config(1, mode="adapters", sim=True), env_ds, text_encoder=HashText(),
            init_model=tmp_path / "bb" / "model").train(progress=False)
    again = Trainer(tmp_path / "again", run_config(1), ds, text_encoder=HashText(),
                    init_model=tmp_path / "ad" / "model")
    assert all(torch.equal(v, start.state_dict()[k]) for k, v in again.network.state_dict().items())
    other = run_config(1)
    other.model.backbone.latent_dim *= 2
    with pytest.raises(SimdiffError, match="backbone config differs"):
        Trainer(tmp_path / "x", other, ds, text_encoder=HashText(), init_model=tmp_path / "bb" / "model")


def test_adapters_warm_start_from_a_simdiff_folder(tmp_path) -> None:
    """``init_adapters``: the Sim Encoder and adapters begin as the folder's, the backbone comes from ``init_model``;
    a backbone-only folder, a different sim config or backbone mode are refused."""
    ds = synthetic_dataset(4, 20, max_frames=20)
    env_ds = synthetic_dataset(4, 20, max_frames=20, with_env=True)
    Trainer(tmp_path / "bb", run_config(2), ds, text_encoder=HashText()).train(progress=False)
    Trainer(tmp_path / "ad", run_config(3, mode="adapters", sim=True), env_ds, text_encoder=HashText(),
            init_model=tmp_path / "bb" / "model").train(progress=False)
    trained = load_file(tmp_path / "ad" / "model" / "model.safetensors")
    assert trained["adapters.0.up.weight"].abs().max() > 0
    Trainer(tmp_path / "bb2", run_config(1, seed=9), ds, text_encoder=HashText()).train(progress=False)
    bb2 = load_file(tmp_path / "bb2" / "model" / "model.safetensors")
    warm = Trainer(tmp_path / "warm", run_config(2, mode="adapters", sim=True), env_ds, text_encoder=HashText(),
                   init_model=tmp_path / "bb2" / "model", init_adapters=tmp_path / "ad" / "model")
    state = warm.network.state_dict()
    for key, value in state.items():
        if key.startswith("backbone."):
            assert torch.equal(value, bb2[key[len("backbone."):]]), key
        else:
            assert torch.equal(value, trained[key]), key
    with pytest.raises(SimdiffError, match="not a SimDiff model"):
        Trainer(tmp_path / "y", run_config(2, mode="adapters", sim=True), env_ds, text_encoder=HashText(),
                init_model=tmp_path / "bb" / "model", init_adapters=tmp_path / "bb" / "model")
    other = run_config(2, mode="adapters", sim=True)
    other.model.sim.hidden *= 2
    with pytest.raises(SimdiffError, match="sim config differs"):
        Trainer(tmp_path / "z", other, env_ds, text_encoder=HashText(), init_model=tmp_path / "bb" / "model",
                init_adapters=tmp_path / "ad" / "model")
    with pytest.raises(SimdiffError, match="needs adapters mode"):
        Trainer(tmp_path / "w", run_config(2), ds, text_encoder=HashText(), init_adapters=tmp_path / "ad" / "model")
