"""GPU packaging on CPU: corpus pack/unpack, weight shards, and the device script's tiny-step rehearsal."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import torch

from simdiff.diffusion.config import SamplingConfig
from simdiff.cli.main import main
from simdiff.data.pack import pack, unpack
from simdiff.errors import SimdiffError
from simdiff.model.checkpoint import build_network, load_pretrained, save_pretrained
from simdiff.model.config import ModelConfig, SimConfig, backbone_preset
from simdiff.inference.generator import MotionGenerator
from simdiff.model.shards import INDEX_NAME, load_sharded, shard_model_folder, shard_tensors
from simdiff.train.testing import HashTextEncoder



pytestmark = pytest.mark.usefixtures("one_torch_thread")


@pytest.fixture(scope="module")
def corpus(tiny_corpus):
    return tiny_corpus


def _clips(folder: Path) -> dict[str, np.ndarray]:
    return {p.stem: np.load(p) for p in sorted((folder / "new_joint_vecs").glob("*.npy"))}


def test_pack_budget_and_bad_inputs(corpus, tmp_path) -> None:
    with pytest.raises(SimdiffError, match="over the 0.01 MiB budget"):
        pack(corpus, tmp_path / "p", budget_mib=0.01)
    assert not (tmp_path / "p").exists()
    with pytest.raises(SimdiffError, match="Mean.npy"):
        pack(tmp_path, tmp_path / "p")
    with pytest.raises(SimdiffError, match="not a simdiff-pack|cannot read pack index"):
        (tmp_path / "bad").mkdir()
        (tmp_path / "bad" / "pack.json").write_text("{}")
        unpack(tmp_path / "bad", tmp_path / "o")
    assert main(["train", "pack", str(corpus), "--out", str(tmp_path / "cli"), "--splits", "test"]) == 0
    assert main(["train", "unpack", str(tmp_path / "cli"), "--out", str(tmp_path / "cli_back")]) == 0
    assert sorted(_clips(tmp_path / "cli_back")) == (corpus / "test.txt").read_text().split()


def test_shards_reassemble_bit_exactly(tmp_path) -> None:
    g = torch.Generator().manual_seed(0)
    tensors = {f"layer{i}.weight": torch.randn(64, 100, generator=g) for i in range(6)}
    tensors["count"] = torch.arange(7)
    files = shard_tensors(tensors, tmp_path, max_bytes=60_000)
    assert len(files) >= 3 and all((tmp_path / f).stat().st_size <= 60_000 for f in files)
    index = json.loads((tmp_path / INDEX_NAME).read_text())
    assert set(index["weight_map"]) == set(tensors)
    back = load_sharded(tmp_path)
    assert all(torch.equal(back[k], v) and back[k].dtype == v.dtype for k, v in tensors.items())
    with pytest.raises(SimdiffError, match="does not fit"):
        shard_tensors({"big": torch.zeros(100_000)}, tmp_path / "big", max_bytes=60_000)
    (tmp_path / files[-1]).unlink()
    with pytest.raises(SimdiffError, match="missing"):
        load_sharded(tmp_path)


def test_sharded_checkpoint_loads_into_the_generator(tmp_path) -> None:
    config = ModelConfig(backbone=backbone_preset("tiny"), sim=SimConfig())
    torch.manual_seed(0)
    net = build_network(config)
    save_pretrained(tmp_path / "whole", net, config, {"normalizer.mean": torch.zeros(263), "normalizer.std": torch.ones(263)})
    shard_model_folder(tmp_path / "whole", tmp_path / "sharded", 200_000)
    assert not (tmp_path / "sharded" / "model.safetensors").exists()
    a, _, extra_a = load_pretrained(tmp_path / "whole")
    b, _, extra_b = load_pretrained(tmp_path / "sharded")
    assert all(torch.equal(x, y) for x, y in zip(a.state_dict().values(), b.state_dict().values()))
    assert torch.equal(extra_a["normalizer.std"], extra_b["normalizer.std"])
    outs = []
    for folder in ("whole", "sharded"):
        gen = MotionGenerator.load(tmp_path / folder, load_text=False)
        gen.text_encoder = HashTextEncoder()
        outs.append(gen.generate(["a person walks"], 20, SamplingConfig(steps=3), env=[-5.0, 0.0, 0.0], seed=1).features)
    assert torch.equal(outs[0], outs[1])
