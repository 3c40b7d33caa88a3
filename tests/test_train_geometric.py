"""MDM's geometric losses (position, velocity, foot contact) and length-cropped batches."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from simdiff.motion.features import process_joints
from simdiff.motion.synthetic import walk
from simdiff.train import Trainer, synthetic_dataset
from simdiff.data.batch import collate
from simdiff.train.geometric import CropConfig, GeometricLossConfig, crop_batch, geometric_loss
from simdiff.train.testing import HashTextEncoder, tiny_run_config


pytestmark = pytest.mark.usefixtures("one_torch_thread")


def _walk_batch() -> tuple[torch.Tensor, torch.Tensor, torch.Tensor, torch.Tensor]:
    feats = process_joints(walk(48, speed=1.2)).features.astype(np.float32)
    mean, std = torch.from_numpy(feats.mean(0)), torch.from_numpy(feats.std(0) + 0.1)
    x = (torch.from_numpy(feats)[None] - mean) / std
    mask = torch.ones(1, x.shape[1], dtype=torch.bool)
    return x, mask, mean, std


def test_geometric_terms_vanish_on_the_target_and_are_off_by_default() -> None:
    x, mask, mean, std = _walk_batch()
    noisy = x + 0.3 * torch.randn(x.shape, generator=torch.Generator().manual_seed(0))
    assert float(geometric_loss(noisy, x, mask, mean, std, GeometricLossConfig())) == 0.0
    full = GeometricLossConfig(position=1.0, velocity=1.0, foot_contact=0.0)
    assert float(geometric_loss(x, x, mask, mean, std, full)) == pytest.approx(0.0, abs=1e-10)
    for cfg in (GeometricLossConfig(position=1.0), GeometricLossConfig(velocity=1.0)):
        assert float(geometric_loss(noisy, x, mask, mean, std, cfg)) > 1e-4


def test_foot_contact_penalises_moving_planted_feet_only() -> None:
    x, mask, mean, std = _walk_batch()
    raw = x * std + mean
    contacts = raw[..., 259:263]
    cfg = GeometricLossConfig(foot_contact=1.0)
    # the target's own feet: the walk's planted feet barely move -> small, but a skating copy (root drifts) is larger
    own = float(geometric_loss(x, x, mask, mean, std, cfg))
    skate = raw.clone()
    skate[..., 2] += 0.05  # +1 m/s forward root velocity everywhere: every planted foot slides
    worse = float(geometric_loss((skate - mean) / std, x, mask, mean, std, cfg))
    assert contacts.sum() > 0 and worse > own + 0.5
    no_contact = raw.clone()
    no_contact[..., 259:263] = 0.0
    assert float(geometric_loss((skate - mean) / std, (no_contact - mean) / std, mask, mean, std, cfg)) == 0.0
    grad_in = x.clone().requires_grad_(True)
    geometric_loss(grad_in, x, mask, mean, std, GeometricLossConfig(1.0, 1.0, 1.0)).backward()
    assert torch.isfinite(grad_in.grad).all()


def test_crop_batch_takes_windows_in_multiples_of_four() -> None:
    motion = torch.arange(2 * 40 * 3, dtype=torch.float32).reshape(2, 40, 3)
    motion[1, 13:] = 0.0
    items = [{"motion": motion[i].numpy(), "length": n, "caption": "x"} for i, n in enumerate((40, 13))]
    batch = crop_batch(collate(items), CropConfig(max_frames=22), np.random.default_rng(0))
    assert batch["motion"].shape == (2, 20, 3) and batch["lengths"].tolist() == [20, 13]
    start = int(batch["motion"][0, 0, 0]) // 3
    assert torch.equal(batch["motion"][0], motion[0, start:start + 20])
    assert torch.equal(batch["motion"][1, :13], motion[1, :13]) and batch["mask"][1].sum() == 13
    trimmed = crop_batch(collate(items[1:]), CropConfig(trim_padding=True), np.random.default_rng(0))
    assert trimmed["motion"].shape[1] == 16
    same = collate(items)
    assert crop_batch(same, CropConfig(), np.random.default_rng(0))["motion"].shape[1] == 40


def test_trainer_with_geometric_losses_and_crops(tmp_path) -> None:
    ds = synthetic_dataset(4, 40, max_frames=60)
    config = tiny_run_config(4, losses=GeometricLossConfig(position=0.1, velocity=0.1, foot_contact=0.1),
                             crop=CropConfig(max_frames=24, trim_padding=True))
    trainer = Trainer(tmp_path, config, ds, text_encoder=HashTextEncoder())
    assert trainer.batch(0)["motion"].shape[1] == 24
    losses = trainer.train(progress=False)
    assert len(losses) == 4 and all(np.isfinite(losses))
    plain = Trainer(tmp_path / "plain", tiny_run_config(1), ds, text_encoder=HashTextEncoder())
    assert plain.batch(0)["motion"].shape[1] == 60
