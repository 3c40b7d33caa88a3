"""The shipped run configs parse, and unknown keys are rejected."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from simdiff.errors import SimdiffError
from simdiff.model.config import config_from_dict
from simdiff.train.config import LR_SCHEDULES, RunConfig

CONFIG_DIR = Path(__file__).resolve().parents[1] / "configs"
CONFIGS = sorted(p for p in CONFIG_DIR.glob("*.json") if not p.name.startswith("eval_"))
EVAL_CONFIGS = sorted(CONFIG_DIR.glob("eval_*.json"))


@pytest.mark.parametrize("path", CONFIGS, ids=[p.stem for p in CONFIGS])
def test_config_parses(path: Path) -> None:
    config = config_from_dict(json.loads(path.read_text()), RunConfig)
    assert config.train.mode in ("backbone", "adapters")
    assert (config.model.sim is not None) == (config.train.mode == "adapters")
    # unmasked attention lets real frames attend to padding (MDM's bug); a run from scratch masks it
    assert config.model.backbone.mask_frames, f"{path.name} trains with unmasked attention"
    assert config.train.optim.lr_schedule in LR_SCHEDULES


@pytest.mark.parametrize("path", EVAL_CONFIGS, ids=[p.stem for p in EVAL_CONFIGS])
def test_experiment_config_parses(path: Path) -> None:
    from simdiff.eval.experiments import load_config

    assert load_config(path) is not None


def test_unknown_key_rejected() -> None:
    with pytest.raises(SimdiffError, match="lr_typo"):
        config_from_dict({"train": {"optim": {"lr_typo": 1}}}, RunConfig)


def test_mdm_config_is_the_papers() -> None:
    config = config_from_dict(json.loads((CONFIGS[0].parent / "backbone_mdm.json").read_text()), RunConfig)
    b = config.model.backbone
    assert (b.latent_dim, b.num_layers, b.num_heads, b.ff_size, b.dropout, b.text_dim) == (512, 8, 4, 1024, 0.1, 512)
    assert (config.train.batch_size, config.train.optim.lr, config.train.seed) == (64, 1e-4, 10)
