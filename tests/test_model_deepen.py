"""``simdiff train deepen``: identity layers inserted into a trained backbone leave x̂₀ unchanged."""

from __future__ import annotations

import json

import pytest
import torch

from simdiff.cli.main import main
from simdiff.model.checkpoint import build_network, load_pretrained, save_pretrained
from simdiff.model.condition import Condition
from simdiff.model.config import BackboneConfig, ModelConfig, SimConfig

pytestmark = pytest.mark.usefixtures("one_torch_thread")


def _trained_like(folder, sim: bool) -> None:
    """A small model whose weights are all random (adapter up-projections and norm affines included)."""
    torch.manual_seed(0)
    config = ModelConfig(backbone=BackboneConfig(latent_dim=32, num_layers=3, num_heads=4, ff_size=48, mask_frames=True),
                         sim=SimConfig() if sim else None)
    net = build_network(config)
    with torch.no_grad():
        for name, p in net.named_parameters():
            if "norm" in name or ".up." in name:
                p.copy_(torch.randn_like(p) * 0.5 + (1.0 if name.endswith("norm1.weight") or name.endswith("norm2.weight") else 0.0))
    extra = {"normalizer.mean": torch.zeros(263), "normalizer.std": torch.ones(263)}
    save_pretrained(folder, net, config, extra)
    (folder / "sampling.json").write_text('{"guidance": 2.5}')


def _outputs(folder, env: bool) -> torch.Tensor:
    net, _, _ = load_pretrained(folder)
    net.eval()
    g = torch.Generator().manual_seed(1)
    x, text = torch.randn(3, 20, 263, generator=g), torch.randn(3, 384, generator=g)
    mask = torch.ones(3, 20, dtype=torch.bool)
    mask[1, 12:] = False
    cond = Condition(text=text, frame_mask=mask,
                     env=torch.tensor([[-1.6, 0.0, 0.0], [-9.81, 10.0, 0.0], [-3.7, 2.0, -1.0]]) if env else None,
                     alpha=torch.tensor([1.0, 0.5, 0.25]) if env else 1.0)
    with torch.no_grad():
        return net(x, torch.tensor([5, 400, 999]), cond)


@pytest.mark.parametrize("sim", [False, True])
@pytest.mark.parametrize("after", [None, [1]])
def test_deepened_model_computes_the_same(tmp_path, capsys, sim, after) -> None:
    src, out = tmp_path / "src", tmp_path / "deep"
    _trained_like(src, sim)
    argv = ["train", "deepen", "--model", str(src), "--out", str(out), "--seed", "3"]
    assert main(argv + (["--after", *map(str, after)] if after else [])) == 0
    layers = json.loads((out / "config.json").read_text())["backbone"]["num_layers"]
    assert layers == (6 if after is None else 4)
    for env in ([False, True] if sim else [False]):
        a, b = _outputs(src, env), _outputs(out, env)
        assert torch.allclose(a, b, atol=2e-4, rtol=1e-4), (a - b).abs().max()
    recipe = json.loads((out / "deepening.json").read_text())
    assert recipe["layers"] == [3, layers] and recipe["after"] == (after or [0, 1, 2]) and len(recipe["model_sha256"]) == 64
    assert (out / "sampling.json").read_text() == '{"guidance": 2.5}'
    capsys.readouterr()


def test_new_layers_receive_gradient(tmp_path) -> None:
    src, out = tmp_path / "src", tmp_path / "deep"
    _trained_like(src, sim=False)
    assert main(["train", "deepen", "--model", str(src), "--out", str(out)]) == 0
    net, _, _ = load_pretrained(out)
    g = torch.Generator().manual_seed(2)
    cond = Condition(text=torch.randn(2, 384, generator=g))
    net(torch.randn(2, 10, 263, generator=g), torch.tensor([3, 700]), cond).square().mean().backward()
    new = net.seqTransEncoder.layers[1]
    assert new.linear2.weight.grad.abs().sum() > 0 and new.self_attn.out_proj.weight.grad.abs().sum() > 0


@pytest.mark.parametrize("argv_tail, message", [
    (["--after", "7"], "--after 7: the model has layers 0..2"),
    (["--same"], "is the same folder as --model"),
])
def test_deepen_errors_are_one_line(tmp_path, capsys, argv_tail, message) -> None:
    src = tmp_path / "src"
    _trained_like(src, sim=False)
    out = src if argv_tail == ["--same"] else tmp_path / "deep"
    tail = [] if argv_tail == ["--same"] else argv_tail
    capsys.readouterr()
    assert main(["train", "deepen", "--model", str(src), "--out", str(out), *tail]) == 2
    err = capsys.readouterr().err.strip()
    assert message in err and "\n" not in err


def test_deepen_is_deterministic_under_its_seed(tmp_path) -> None:
    from simdiff.model.deepen import deepen_model

    src = tmp_path / "src"
    _trained_like(src, sim=True)
    torch.manual_seed(123)  # the global RNG's state must not matter
    for name, seed in (("a", 5), ("b", 5), ("c", 6)):
        deepen_model(src, tmp_path / name, seed=seed)
        torch.rand(7)
    from safetensors.torch import load_file

    w = {n: load_file(str(tmp_path / n / "model.safetensors")) for n in "abc"}
    assert (tmp_path / "a" / "model.safetensors").read_bytes() == (tmp_path / "b" / "model.safetensors").read_bytes()
    assert not all(torch.equal(v, w["c"][k]) for k, v in w["a"].items())


def test_deepen_reads_a_sharded_model(tmp_path) -> None:
    """A sharded folder (what a GPU run brings back) deepens like the whole one; its recipe names the shards' digest."""
    from simdiff.model.shards import shard_model_folder, weights_sha256

    src, sharded = tmp_path / "src", tmp_path / "sharded"
    _trained_like(src, sim=True)
    assert len(shard_model_folder(src, sharded, 100_000)) > 1
    for name, folder in (("whole", src), ("parts", sharded)):
        assert main(["train", "deepen", "--model", str(folder), "--out", str(tmp_path / name), "--seed", "1"]) == 0
    assert torch.equal(_outputs(tmp_path / "whole", True), _outputs(tmp_path / "parts", True))
    recipe = json.loads((tmp_path / "parts" / "deepening.json").read_text())
    assert recipe["model_sha256"] == weights_sha256(sharded) != weights_sha256(src)


def test_weights_digest_follows_every_shard(tmp_path) -> None:
    from simdiff.errors import SimdiffError
    from simdiff.model.shards import shard_model_folder, weights_sha256

    src, sharded = tmp_path / "src", tmp_path / "sharded"
    _trained_like(src, sim=False)
    shards = shard_model_folder(src, sharded, 100_000)
    before = weights_sha256(sharded)
    last = sharded / shards[-1]
    last.write_bytes(last.read_bytes()[:-1] + b"\0")
    assert weights_sha256(sharded) != before
    last.unlink()
    with pytest.raises(SimdiffError, match="shard named in"):
        weights_sha256(sharded)
    with pytest.raises(SimdiffError, match="no model.safetensors"):
        weights_sha256(tmp_path)
