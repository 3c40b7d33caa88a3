"""The default-model loader: folder precedence, missing/corrupt files and the shipped weights."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import torch

from simdiff.diffusion.config import SamplingConfig
from simdiff.errors import SimdiffError
from simdiff.inference import default
from simdiff.inference.default import DEFAULT_MODEL_DIR, check_model_dir, default_model_dir, load_default


def test_folder_precedence(tmp_path: Path, monkeypatch) -> None:
    monkeypatch.delenv("SIMDIFF_MODEL", raising=False)
    assert default_model_dir() == DEFAULT_MODEL_DIR
    assert DEFAULT_MODEL_DIR.parts[-3:] == ("simdiff", "assets", "default_model")
    monkeypatch.setenv("SIMDIFF_MODEL", str(tmp_path / "env"))
    assert default_model_dir() == tmp_path / "env"
    assert default_model_dir(tmp_path / "arg") == tmp_path / "arg"


def test_missing_and_corrupt_files(tmp_path: Path) -> None:
    with pytest.raises(SimdiffError, match="config.json: model file not found"):
        check_model_dir(tmp_path)
    (tmp_path / "config.json").write_text("{}")
    with pytest.raises(SimdiffError, match="model.safetensors: model file not found"):
        load_default(tmp_path)
    (tmp_path / "model.safetensors").write_bytes(b"\x00" * 16)
    with pytest.raises(SimdiffError, match=r"cannot load model") as info:
        load_default(tmp_path, load_text=False)
    assert str(tmp_path) in str(info.value) and "\n" not in str(info.value)


def test_load_a_saved_tiny_model(tmp_path: Path) -> None:
    from simdiff.model import ModelConfig, SimConfig, backbone_preset, build_network
    from simdiff.inference.generator import MotionGenerator

    config = ModelConfig(backbone=backbone_preset("tiny"), sim=SimConfig())
    MotionGenerator(build_network(config), config, mean=torch.full((263,), 0.5)).save(tmp_path)
    gen = load_default(tmp_path, load_text=False)
    assert gen.is_simdiff and gen.text_encoder is None and float(gen.mean[0]) == 0.5


@pytest.mark.skipif(not (default.DEFAULT_MODEL_DIR / "model.safetensors").is_file(),
                    reason="the shipped default model (simdiff/assets/default_model/) is not installed yet")
def test_shipped_default_model_generates() -> None:
    from simdiff.motion.features import features_to_joints

    gen = load_default(DEFAULT_MODEL_DIR)
    assert gen.is_simdiff and gen.config.sim.mode == "continuous" and gen.config.text_encoder == "minilm"
    out = gen.generate(["a person jumps forward"], 40, SamplingConfig(steps=10), env=(-3.7, 2.0, 0.0), seed=0)
    joints = features_to_joints(out.clips()[0].numpy())
    assert joints.shape == (40, 22, 3) and np.isfinite(joints).all()
    height = joints[:, 15, 1].mean() - joints[..., 1].min(axis=1).mean()  # head above the lowest joint
    assert 1.0 < height < 2.2, height  # a trained model makes a human-sized figure
