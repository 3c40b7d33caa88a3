"""Hostile inputs refused with one line (``simdiff: error: …``, exit 2), never a traceback: output folders equal to an
input, devices this machine lacks, broken model folders, broken training and experiment configs."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
import torch

from simdiff.cli.main import main
from simdiff.errors import SimdiffError


from test_generate_cli import save_tiny  # noqa: E402 - the shared tiny-model fixture


@pytest.fixture(scope="module")
def tiny_model(tmp_path_factory) -> Path:
    return save_tiny(tmp_path_factory.mktemp("robust_tiny"))


def one_line_error(argv: list[str], capsys) -> str:
    """Run the CLI; assert exit 2 and a single ``simdiff: error:`` line; return that line."""
    capsys.readouterr()
    code = main(argv)
    err = capsys.readouterr().err
    assert code == 2, err
    assert err.startswith("simdiff: error: ") and err.count("\n") == 1, err
    assert "Traceback" not in err
    return err


def snapshot(folder: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir()) if p.is_file()}


# --- output folder equal to (or inside) an input ----------------------------------------------------------------


@pytest.mark.parametrize("command", ["export-backbone", "deepen", "precision"])
@pytest.mark.parametrize("where", ["same", "inside"])
def test_derived_model_out_must_differ_from_model(tiny_model, tmp_path, capsys, command, where) -> None:
    model = shutil.copytree(tiny_model, tmp_path / "m")
    before = snapshot(model)
    out = model if where == "same" else model / "sub"
    err = one_line_error(["train", command, "--model", str(model), "--out", str(out)], capsys)
    assert "--out" in err and "--model" in err
    assert snapshot(model) == before and not (model / "sub").exists()


@pytest.mark.parametrize("target", ["model", "parent"])
def test_extrapolate_out_must_differ_from_both_inputs(tiny_model, tmp_path, capsys, target) -> None:
    model = shutil.copytree(tiny_model, tmp_path / "m")
    parent = shutil.copytree(tiny_model, tmp_path / "p")
    before = snapshot(model), snapshot(parent)
    out = model if target == "model" else parent
    err = one_line_error(["train", "extrapolate", "--model", str(model), "--parent", str(parent), "--lam", "2",
                          "--out", str(out)], capsys)
    assert f"--{target}" in err
    assert (snapshot(model), snapshot(parent)) == before


def test_out_holding_the_model_is_refused(tiny_model, tmp_path, capsys) -> None:
    model = shutil.copytree(tiny_model, tmp_path / "runs" / "m")
    err = one_line_error(["train", "precision", "--model", str(model), "--out", str(tmp_path / "runs")], capsys)
    assert "holds" in err


@pytest.mark.parametrize("command", ["pack", "unpack"])
def test_pack_and_unpack_out_must_differ_from_input(tmp_path, capsys, command) -> None:
    folder = tmp_path / "corpus"
    folder.mkdir()
    (folder / "keep.txt").write_text("x")
    err = one_line_error(["train", command, str(folder), "--out", str(folder)], capsys)
    assert "same folder" in err
    assert (folder / "keep.txt").read_text() == "x"


def test_check_separate_resolves_paths(tmp_path, monkeypatch) -> None:
    from simdiff.cli.paths import check_separate

    (tmp_path / "a").mkdir()
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SimdiffError, match="same folder"):
        check_separate("a/../a", model=tmp_path / "a")
    check_separate(tmp_path / "b", model=tmp_path / "a", parent=None)  # siblings are fine


# --- devices -----------------------------------------------------------------------------------------------------


def test_torch_device_accepts_cpu_and_refuses_others() -> None:
    from simdiff.inference.device import torch_device

    assert torch_device("cpu") == torch.device("cpu")
    for name in ("meta", "garbage", "cuda:x", "cpu:0:1", ""):
        with pytest.raises(SimdiffError, match="--device"):
            torch_device(name)
    with pytest.raises(SimdiffError, match="cuda:99"):
        torch_device("cuda:99")
    if not torch.cuda.is_available():
        with pytest.raises(SimdiffError, match="--device cuda: .*; use --device cpu"):
            torch_device("cuda")
    if not (hasattr(torch.backends, "mps") and torch.backends.mps.is_available()):
        with pytest.raises(SimdiffError, match="mps"):
            torch_device("mps")


BAD_DEVICES = ["meta", "garbage", "cuda:99"] + ([] if torch.cuda.is_available() else ["cuda"])


@pytest.mark.parametrize("device", BAD_DEVICES)
def test_sample_refuses_unusable_device(tiny_model, tmp_path, capsys, device) -> None:
    err = one_line_error(["sample", "--model", str(tiny_model), "--text", "a person walks", "--length", "20",
                          "--steps", "1", "--device", device, "--out", str(tmp_path / "s"), "--no-progress"], capsys)
    assert "--device" in err
    assert not (tmp_path / "s").exists()


@pytest.mark.parametrize("device", BAD_DEVICES)
def test_train_refuses_unusable_device(tmp_path, capsys, device) -> None:
    err = one_line_error(["train", "backbone", "--synthetic", "2", "--size", "tiny", "--steps", "1",
                          "--out", str(tmp_path / "run"), "--device", device, "--no-progress"], capsys)
    assert "--device" in err


def test_train_evaluator_refuses_unusable_device(tmp_path, capsys) -> None:
    err = one_line_error(["evaluate", "train-evaluator", "--corpus", str(tmp_path / "c"), "--out", str(tmp_path / "e"),
                          "--device", "meta", "--no-progress"], capsys)
    assert "--device" in err


@pytest.mark.skipif(torch.cuda.is_available(), reason="this machine has CUDA")
def test_generate_device_message_is_plain(tiny_model, tmp_path, capsys) -> None:
    err = one_line_error(["generate", "a person walks", "--model", str(tiny_model), "--length", "1", "--steps", "1",
                          "--device", "cuda", "--out", str(tmp_path / "g"), "-q"], capsys)
    assert "no CUDA" in err and "--device cpu" in err
    assert "AssertionError" not in err and "Torch not compiled" not in err


def test_serve_refuses_unusable_device(capsys) -> None:
    import argparse

    from simdiff.cli.commands.serve import build_server

    args = argparse.Namespace(port=0, queue=1, steps=None, device="meta", files=[], model=None, host="127.0.0.1")
    with pytest.raises(SimdiffError, match="--device"):
        build_server(args)


# --- broken model folders ----------------------------------------------------------------------------------------


def _edit_config(folder: Path, change) -> None:
    path = folder / "config.json"
    if isinstance(change, str):
        path.write_text(change)
        return
    data = json.loads(path.read_text())
    change(data)
    path.write_text(json.dumps(data))


def _set(section: str, key: str, value):
    def change(data):
        data[section][key] = value
    return change


BROKEN_CONFIGS = {
    "invalid-json": ("{not json", "invalid JSON"),
    "array": ("[1, 2]", "JSON object"),
    "null": ("null", "JSON object"),
    "string-latent": (_set("backbone", "latent_dim", "256"), "backbone.latent_dim"),
    "heads-zero": (_set("backbone", "num_heads", 0), "backbone.num_heads"),
    "heads-not-dividing": (_set("backbone", "num_heads", 3), "backbone.num_heads = 3 does not divide latent_dim 64"),
    "short-table": (_set("backbone", "max_len", 5), "backbone.max_len = 5"),
    "huge-depth": (_set("backbone", "num_layers", 10**9), "backbone.num_layers"),
    "float-depth": (_set("backbone", "num_layers", 1e9), "backbone.num_layers"),
    "nfeats": (_set("backbone", "nfeats", 10), "backbone.nfeats"),
    "dropout": (_set("backbone", "dropout", 1.5), "backbone.dropout"),
    "unknown-key": (_set("backbone", "bogus", 1), "backbone.bogus"),
    "gravity-scale": (_set("sim", "gravity_scale", 0), "sim.gravity_scale"),
    "sim-array": (lambda d: d.__setitem__("sim", [1]), "sim"),
}


@pytest.mark.parametrize("case", sorted(BROKEN_CONFIGS))
def test_sample_refuses_broken_config(tiny_model, tmp_path, capsys, case) -> None:
    model = shutil.copytree(tiny_model, tmp_path / "m")
    change, expected = BROKEN_CONFIGS[case]
    _edit_config(model, change)
    err = one_line_error(["sample", "--model", str(model), "--text", "a person walks", "--length", "20",
                          "--steps", "1", "--out", str(tmp_path / "s"), "--no-progress"], capsys)
    assert "config.json" in err and expected in err
    for name in ("Error:", "ModelConfig", "BackboneConfig", "SimConfig", "TypeError"):
        assert name not in err


@pytest.mark.parametrize("argv", [
    ["train", "export-backbone", "--model", "{m}", "--out", "{o}"],
    ["train", "deepen", "--model", "{m}", "--out", "{o}"],
    ["train", "precision", "--model", "{m}", "--out", "{o}"],
    ["train", "extrapolate", "--model", "{m}", "--parent", "{m}", "--lam", "1", "--out", "{o}"],
    ["generate", "a person walks", "--model", "{m}", "--length", "1", "--steps", "1", "--out", "{o}", "-q"],
    ["train", "backbone", "--synthetic", "2", "--init", "{m}", "--steps", "1", "--out", "{o}", "--no-progress"],
    ["train", "adapters", "--synthetic", "2", "--init", "{m}", "--steps", "1", "--out", "{o}", "--no-progress"],
    ["train", "adapters", "--synthetic", "2", "--adapters-init", "{m}", "--steps", "1", "--out", "{o}",
     "--no-progress"],
])
def test_every_loading_command_checks_the_config(tiny_model, tmp_path, capsys, argv) -> None:
    model = shutil.copytree(tiny_model, tmp_path / "m")
    _edit_config(model, _set("backbone", "num_heads", 3))
    argv = [a.format(m=model, o=tmp_path / "o") for a in argv]
    err = one_line_error(argv, capsys)
    assert "config.json: backbone.num_heads = 3 does not divide latent_dim 64" in err


def test_safetensors_header_claiming_huge_size(tiny_model, tmp_path, capsys) -> None:
    model = shutil.copytree(tiny_model, tmp_path / "m")
    (model / "model.safetensors").write_bytes((10**15).to_bytes(8, "little") + b"{}")
    err = one_line_error(["train", "precision", "--model", str(model), "--out", str(tmp_path / "o")], capsys)
    assert "model.safetensors" in err


def test_truncated_safetensors(tiny_model, tmp_path, capsys) -> None:
    model = shutil.copytree(tiny_model, tmp_path / "m")
    data = (model / "model.safetensors").read_bytes()
    (model / "model.safetensors").write_bytes(data[: len(data) // 2])
    err = one_line_error(["sample", "--model", str(model), "--text", "a", "--length", "20", "--steps", "1",
                          "--out", str(tmp_path / "s"), "--no-progress"], capsys)
    assert "model.safetensors" in err


def test_nan_weights_refused_at_load(tiny_model, tmp_path, capsys) -> None:
    from safetensors.torch import load_file, save_file

    model = shutil.copytree(tiny_model, tmp_path / "m")
    weights = load_file(str(model / "model.safetensors"))
    key = next(k for k in sorted(weights) if weights[k].is_floating_point() and not k.startswith("normalizer."))
    weights[key] = torch.full_like(weights[key], float("nan"))
    save_file(weights, str(model / "model.safetensors"))
    err = one_line_error(["generate", "a person walks", "--model", str(model), "--length", "1", "--steps", "1",
                          "--out", str(tmp_path / "g"), "-q"], capsys)
    assert f"model.safetensors: weight {key} has NaN values" in err


def test_valid_model_still_loads(tiny_model) -> None:
    from simdiff.model.checkpoint import load_pretrained

    network, config, extra = load_pretrained(tiny_model)
    assert config.backbone.num_heads == 4 and "normalizer.std" in extra


# --- training and experiment configs -----------------------------------------------------------------------------


BAD_RUN_CONFIGS = {
    "array": ([], "JSON object"),
    "null": (None, "JSON object"),
    "number": (3, "JSON object"),
    "unknown-top": ({"bogus": 1}, "bogus"),
    "unknown-train": ({"train": {"lr": 1}}, "train.lr"),
    "unknown-model": ({"model": {"backbone": {"layers": 2}}}, "model.backbone.layers"),
    "string-steps": ({"train": {"steps": "10"}}, "train.steps"),
    "batch-zero": ({"train": {"batch_size": 0}}, "train.batch_size"),
    "cond-mask": ({"train": {"cond_mask_prob": 1.5}}, "train.cond_mask_prob"),
    "crop-long": ({"train": {"crop": {"max_frames": 500}}}, "train.crop.max_frames"),
    "crop-negative": ({"train": {"crop": {"max_frames": -4}}}, "train.crop.max_frames"),
    "loss-negative": ({"train": {"losses": {"position": -1}}}, "train.losses.position"),
    "keep-zero": ({"train": {"keep_checkpoints": 0}}, "train.keep_checkpoints"),
    "grad-clip": ({"train": {"optim": {"grad_clip": -1}}}, "train.optim.grad_clip"),
    "betas-one": ({"train": {"optim": {"betas": [0.9]}}}, "train.optim.betas"),
    "betas-range": ({"train": {"optim": {"betas": [0.9, 1.5]}}}, "train.optim.betas"),
    "ema-decay": ({"train": {"ema_decay": "x"}}, "train.ema_decay"),
    "ema-decay-range": ({"train": {"ema_decay": 2}}, "train.ema_decay"),
    "model-null": ({"model": None}, "model"),
    "heads": ({"model": {"backbone": {"num_heads": 3}}}, "model.backbone.num_heads = 3"),
}


@pytest.mark.parametrize("case", sorted(BAD_RUN_CONFIGS))
def test_train_config_file_is_checked(tmp_path, capsys, case) -> None:
    content, expected = BAD_RUN_CONFIGS[case]
    path = tmp_path / "run.json"
    path.write_text(json.dumps(content))
    err = one_line_error(["train", "backbone", "--synthetic", "2", "--config", str(path), "--out", str(tmp_path / "o"),
                          "--no-progress"], capsys)
    assert str(path) in err and expected in err
    for name in ("RunConfig", "TrainConfig", "ModelConfig", "OptimConfig", "Error:"):
        assert name not in err


def test_loss_weight_nan_is_refused(tmp_path, capsys) -> None:
    path = tmp_path / "run.json"
    path.write_text('{"train": {"losses": {"velocity": NaN}}}')
    err = one_line_error(["train", "backbone", "--synthetic", "2", "--config", str(path), "--out", str(tmp_path / "o"),
                          "--no-progress"], capsys)
    assert "train.losses.velocity" in err


@pytest.mark.parametrize("content", ["[]", "null", "{\"bogus\": 1}"])
def test_pipeline_config_file_is_checked(tmp_path, capsys, content) -> None:
    path = tmp_path / "pipe.json"
    path.write_text(content)
    err = one_line_error(["train", "pipeline", "--out", str(tmp_path / "o"), "--config", str(path), "--dry-run"],
                         capsys)
    assert str(path) in err
    assert "PipelineConfig" not in err


@pytest.mark.parametrize("content", ["[]", "null", "3"])
def test_experiment_config_must_be_an_object(tmp_path, capsys, content) -> None:
    path = tmp_path / "eval_x.json"
    path.write_text(content)
    err = one_line_error(["evaluate", "run", str(path), "--dry-run"], capsys)
    assert str(path) in err and "JSON object" in err


# --- text inputs, experiment names --------------------------------------------------------------------------------


def test_text_table_binary_captions(tmp_path, capsys) -> None:
    corpus = tmp_path / "c"
    (corpus / "texts").mkdir(parents=True)
    (corpus / "texts" / "a.txt").write_text("a person walks#a/DET person/NOUN walk/VERB#0.0#0.0\n")
    captions = tmp_path / "f.png"
    captions.write_bytes(b"\x89PNG\r\n\x1a\n\xff\xfe\x00\x80")
    err = one_line_error(["train", "text-table", str(corpus), "--out", str(tmp_path / "t.safetensors"),
                          "--captions", str(captions)], capsys)
    assert "--captions" in err and "f.png" in err and "UnicodeDecodeError" not in err


def test_missing_clip_weights_names_the_flag(tiny_model, tmp_path, capsys) -> None:
    missing = tmp_path / "nonexistent"
    err = one_line_error(["sample", "--model", str(tiny_model), "--text", "a", "--length", "20", "--steps", "1",
                          "--clip-weights", str(missing), "--out", str(tmp_path / "s"), "--no-progress"], capsys)
    assert f"--clip-weights {missing}" in err and "MiniLM" not in err


@pytest.mark.parametrize("dry_run", [False, True])
def test_evaluate_all_refuses_unknown_experiment(tmp_path, capsys, dry_run) -> None:
    argv = ["evaluate", "all", "--only", "nope", "--configs", str(tmp_path)] + (["--dry-run"] if dry_run else [])
    err = one_line_error(argv, capsys)
    assert "nope" in err and "table1" in err and "env_response" in err
