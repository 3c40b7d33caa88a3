"""A tiny model overfits four clips; DDIM samples reproduce them in joint space."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import torch

from simdiff.diffusion.config import SamplingConfig
from simdiff.inference.generator import MotionGenerator
from simdiff.motion import synthetic
from simdiff.motion.features import features_to_joints, joints_to_features
from simdiff.motion.normalize import Normalizer
from simdiff.train import TensorMotionDataset, Trainer
from simdiff.train.testing import HashTextEncoder as HashText
from simdiff.train.testing import tiny_run_config as run_config

FRAMES = 40
CAPTIONS = ["a person walks forward", "a person walks in a circle", "a person jumps", "a person walks slowly"]


def _clips() -> list[np.ndarray]:
    joints = [synthetic.walk(FRAMES + 1), synthetic.walk(FRAMES + 1, turn_rate=1.0), synthetic.jump(FRAMES + 1),
              synthetic.walk(FRAMES + 1, speed=0.5, stride_hz=0.6)]
    return [joints_to_features(j) for j in joints]


def test_tiny_model_overfits_and_ddim_reproduces_clips(tmp_path) -> None:
    threads = torch.get_num_threads()
    torch.set_num_threads(1)
    try:
        _overfit(tmp_path)
    finally:
        torch.set_num_threads(threads)


def _overfit(tmp_path: Path) -> None:
    feats = _clips()
    norm = Normalizer.fit(feats)
    ds = TensorMotionDataset([norm.normalize(f) for f in feats], CAPTIONS, max_frames=FRAMES)
    cfg = run_config(800, dropout=0.0, lr=1e-3, seed=0)
    trainer = Trainer(tmp_path, cfg, ds, text_encoder=HashText(),
                      mean=torch.from_numpy(norm.mean), std=torch.from_numpy(norm.std))
    losses = trainer.train(progress=False)
    assert np.mean(losses[-50:]) < 0.1 * np.mean(losses[:20])

    gen = MotionGenerator.load(tmp_path / "model", load_text=False)
    gen.text_encoder = HashText()
    out = gen.generate(CAPTIONS, FRAMES, SamplingConfig(), seed=0)
    truth = [features_to_joints(torch.from_numpy(f).double()) for f in feats]
    for i, motion in enumerate(out.features):
        joints = features_to_joints(motion.double())
        errors = [float((joints - t).norm(dim=-1).mean()) for t in truth]
        assert int(np.argmin(errors)) == i, errors  # each sample is its own training clip
        assert errors[i] < 0.3, errors  # mean per-joint error in metres
        assert errors[i] < 0.5 * sorted(errors)[1], errors
