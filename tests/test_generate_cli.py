"""``simdiff generate`` end to end on a tiny saved model (real MiniLM text encoder), and its one-line errors."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import torch

from simdiff.cli.main import main
from simdiff.motion.foot_lock import clean_feet_numpy
from simdiff.model import ModelConfig, SimConfig, backbone_preset, build_network
from simdiff.inference.generator import MotionGenerator


@pytest.fixture(autouse=True)
def restore_threads():
    threads = torch.get_num_threads()
    yield
    torch.set_num_threads(threads)


def save_tiny(folder: Path, sim: bool = True) -> Path:
    torch.manual_seed(0)
    config = ModelConfig(backbone=backbone_preset("tiny"), sim=SimConfig() if sim else None)
    MotionGenerator(build_network(config), config, std=torch.full((263,), 0.05)).save(folder)
    return folder


@pytest.fixture(scope="module")
def tiny_model(tmp_path_factory) -> Path:
    return save_tiny(tmp_path_factory.mktemp("tiny_sim"))


def test_generate_end_to_end(tiny_model: Path, tmp_path: Path, capsys) -> None:
    (tiny_model / "sampling.json").write_text('{"alpha": 0.5, "foot_lock": 1.0}')
    try:
        code = main(["generate", "a person jumps forward", "--gravity", "-3.7", "--wind", "2", "0", "--length", "0.5",
                     "--steps", "2", "--model", str(tiny_model), "--out", str(tmp_path / "o"),
                     "--format", "npy,bvh,gif", "-q"])
    finally:
        (tiny_model / "sampling.json").unlink()
    captured = capsys.readouterr()
    assert code == 0, captured.err
    # quiet: no bars, no notes; only warnings about the motion itself (this random tiny model may glide)
    assert all(line.startswith("simdiff: warning: ") for line in captured.err.splitlines()), captured.err
    printed = captured.out.split()
    assert [Path(p).name for p in printed] == ["sample0.bvh", "sample0.gif", "sample0_features.npy",
                                               "sample0_joints.npy", "generation.json"]
    assert all(Path(p).is_file() for p in printed)
    assert np.load(tmp_path / "o" / "sample0_joints.npy").shape == (10, 22, 3)
    meta = json.loads((tmp_path / "o" / "generation.json").read_text())
    assert (meta["alpha"], meta["steps"], meta["frames"]) == (0.5, 2, 10)
    assert meta["foot_lock"] == 1.0 and meta["foot_cleanup"] == 4  # swing clearance, floating clip dropped, planted feet held by leg IK
    assert meta["model"]["path"] == str(tiny_model.resolve()) and meta["timings_s"]["load_model"] > 0
    assert meta["threads"] == torch.get_num_threads()
    assert (meta["model"]["trained_on"], meta["model"]["weights_licence"]) == ("unknown", "unknown")  # no provenance.json
    assert meta["samples"][0]["touches_floor"] is True and abs(meta["samples"][0]["lowest_m"]) < 0.1


def test_generate_reports_the_models_provenance(tmp_path: Path, capsys) -> None:
    from simdiff.model.provenance import Provenance, TrainingData, write_provenance

    model = save_tiny(tmp_path / "m")
    write_provenance(model, Provenance([TrainingData("backbone", "corpus", ["bandai"], 0.5, {"CC-BY-NC-4.0": 0.5}),
                                        TrainingData("adapters", "aug", ["cmu-amc"], 0.1, {"CMU": 0.1})]))
    argv = ["generate", "a person waves", "--length", "0.5", "--steps", "2", "--model", str(model),
            "--format", "npy", "-q"]
    assert main([*argv, "--out", str(tmp_path / "o")]) == 0, capsys.readouterr().err
    meta = json.loads((tmp_path / "o" / "generation.json").read_text())["model"]
    assert meta["weights_licence"] == "non-commercial (CC-BY-NC-4.0 motion in the training data)"
    assert [(p["what"], p["data"], p["licences"]) for p in meta["trained_on"]] == [
        ("backbone", "corpus", {"CC-BY-NC-4.0": 0.5}), ("adapters", "aug", {"CMU": 0.1})]
    (model / "provenance.json").write_text("{oops")  # malformed: one line, before any sampling
    capsys.readouterr()  # the good run's own warnings (the tiny model's sample may glide)
    assert main([*argv, "--out", str(tmp_path / "bad")]) == 2
    err = capsys.readouterr().err
    assert "provenance.json: cannot read JSON" in err and err.count("\n") == 1
    assert not (tmp_path / "bad" / "generation.json").exists()


def test_backbone_model_warns_once_and_ignores_phi(tmp_path: Path, capsys) -> None:
    model = save_tiny(tmp_path / "bb", sim=False)
    code = main(["generate", "a person walks", "--gravity", "-1.6", "--compare", "gravity=-9.81,-1.6", "--length", "0.5",
                 "--steps", "1", "--model", str(model), "--out", str(tmp_path / "o"), "--format", "npy,bvh", "-q"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 0
    assert len(err) == 1 and err[0].startswith("simdiff: warning:") and "--gravity, --compare ignored" in err[0]
    assert sorted(p.name for p in (tmp_path / "o").iterdir()) == [
        "generation.json", "sample0.bvh", "sample0_features.npy", "sample0_joints.npy"]


def test_default_output_folder_is_named_after_the_prompt(tiny_model: Path, tmp_path: Path, monkeypatch, capsys) -> None:
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("SIMDIFF_MODEL", str(tiny_model))
    assert main(["generate", "A person: waves!", "--length", "0.5", "--steps", "1", "--format", "npy",
                 "-q"]) == 0
    assert (tmp_path / "out" / "a_person_waves" / "sample0_joints.npy").is_file()
    assert main(["generate", "A person waves", "--length", "0.5", "--steps", "1", "--format", "npy",
                 "-q"]) == 0  # a second run never overwrites the first
    assert (tmp_path / "out" / "a_person_waves-2" / "generation.json").is_file()
    assert capsys.readouterr().out.split()[-1] == "out/a_person_waves-2/generation.json"


@pytest.mark.parametrize("argv, needle", [
    (["   "], "text prompt is empty"),
    (["walk", "--length", "12"], "argument --length: 12 is outside [0.5, 9.8]"),
    (["walk", "--gravity", "0"], "argument --gravity: 0 is outside [-100, -0.1]"),
    (["walk", "--gravity", "nan"], "argument --gravity: 'nan' is not a finite number"),
    (["walk", "--wind", "12", "0"], "12 N exceeds"),
    (["walk", "--steps", "0"], "argument --steps: 0 is outside 1..1000"),
    (["walk", "--guidance", "nan"], "argument --guidance: 'nan' is not a finite number"),
    (["walk", "--compare", "gravity:-1,-2"], "bad --compare 'gravity:-1,-2'"),
    (["walk", "--model", "{tmp}/nowhere"], "nowhere/config.json: model file not found"),
    (["walk", "--model", "{tmp}/corrupt"], "corrupt: cannot load model"),
])
def test_bad_input_one_line_exit_2(tmp_path: Path, argv: list[str], needle: str, capsys) -> None:
    corrupt = save_tiny(tmp_path / "corrupt")
    (corrupt / "model.safetensors").write_bytes(b"not a safetensors file")
    argv = [a.format(tmp=tmp_path) for a in argv]
    code = main(["generate", *argv, "--out", str(tmp_path / "o"), "-q"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2
    assert len(err) == 1 and err[0].startswith("simdiff: error:") and needle in err[0], err


def test_missing_shipped_model_message(tmp_path: Path, monkeypatch) -> None:
    from simdiff.inference import default

    monkeypatch.delenv("SIMDIFF_MODEL", raising=False)
    monkeypatch.setattr(default, "DEFAULT_MODEL_DIR", tmp_path / "default_model")
    from simdiff.errors import SimdiffError

    with pytest.raises(SimdiffError, match="no default model installed .*pass --model DIR or set SIMDIFF_MODEL"):
        default.check_model_dir()


def test_help_lists_every_option_with_the_shipped_defaults() -> None:
    import re

    proc = subprocess.run([sys.executable, "-m", "simdiff", "generate", "--help"], capture_output=True, text=True)
    assert proc.returncode == 0
    options = ("-h", "--gravity", "--wind", "--compare", "--simulate", "--force", "--length", "--seed",
               "--num-samples", "--sampler", "--steps", "--eta", "--guidance", "--guidance-min-t", "--alpha", "--foot-lock",
               "--env-guidance", "--edit-t", "--flight-passes", "--keyframes", "--timeline", "--out", "--format",
               "--quiet", "--model", "--device")
    usage = proc.stdout.split("\n\n")[0]
    assert set(re.findall(r"\[(-[-\w]+)", usage)) == set(options) - {"--quiet"} | {"-q"}
    for default in ("(default 3)", "(default 0.925)", "(default 1.3)", "(default 950)", "(default 1)", "(default 16;",
                    "default 749;"):
        assert default in " ".join(proc.stdout.split()), default


def test_generate_simulate_writes_the_simulated_motion_and_tracking(tiny_model: Path, tmp_path: Path, capsys) -> None:
    code = main(["generate", "a person jumps", "--gravity", "-3.7", "--length", "0.5", "--steps", "1", "--simulate",
                 "--model", str(tiny_model), "--out", str(tmp_path / "o"), "--format", "npy", "-q"])
    captured = capsys.readouterr()
    assert code == 0, captured.err
    assert ("warning: the simulated finish" in captured.err) == (json.loads(
        (tmp_path / "o" / "sample0_tracking.json").read_text())["status"] != "ok")
    names = [Path(p).name for p in captured.out.split()]
    assert "sample0_simulated_joints.npy" in names and "sample0_tracking.json" in names
    sim = np.load(tmp_path / "o" / "sample0_simulated_joints.npy")
    assert sim.ndim == 3 and sim.shape[1:] == (22, 3) and sim.dtype == np.float32 and np.isfinite(sim).all()
    tracking = json.loads((tmp_path / "o" / "sample0_tracking.json").read_text())
    assert tracking["env"] == [-3.7, 0.0, 0.0] and tracking["status"] in ("ok", "fell", "unstable")
    assert tracking["n_frames"] == 10 and tracking["n_out"] == len(sim) and tracking["wall_s"] > 0
    assert set(tracking["physics_generated"]) >= {"penetration", "floating", "sliding"}
    meta = json.loads((tmp_path / "o" / "generation.json").read_text())
    assert meta["samples"][0]["simulated"]["status"] == tracking["status"] and meta["timings_s"]["simulate"] > 0
    # the finish's second try: made exactly when the first rollout fell or slid > 0.5 mm/frame, and recorded
    first_ok = tracking["attempts"] == 1
    assert first_ok == (tracking["status"] == "ok" and tracking["physics_simulated"]["sliding"] <= 0.5)
    assert not (first_ok and tracking["fallback"])
    summary = meta["samples"][0]["simulated"]
    assert (summary["attempts"], summary["fallback"]) == (tracking["attempts"], tracking["fallback"])


def test_generate_simulate_in_a_worker_equals_in_process(tiny_model: Path, tmp_path: Path, capsys,
                                                         monkeypatch: pytest.MonkeyPatch) -> None:
    out = {}
    for workers in ("1", "0"):
        monkeypatch.setenv("SIMDIFF_FINISH_WORKERS", workers)
        code = main(["generate", "a person walks", "--length", "0.5", "--steps", "1", "--simulate", "--model",
                     str(tiny_model), "--out", str(tmp_path / workers), "--format", "npy", "-q"])
        assert code == 0, capsys.readouterr().err
        assert json.loads((tmp_path / workers / "generation.json").read_text())["simulate_workers"] == int(workers)
        out[workers] = np.load(tmp_path / workers / "sample0_simulated_joints.npy")
    np.testing.assert_array_equal(out["1"], out["0"])


def test_a_failed_finish_still_writes_the_generated_motion(tiny_model: Path, tmp_path: Path, capsys,
                                                           monkeypatch: pytest.MonkeyPatch) -> None:
    from simdiff.errors import SimdiffError

    def broken(*args, **kwargs):
        raise SimdiffError("the simulator broke")

    monkeypatch.setenv("SIMDIFF_FINISH_WORKERS", "0")
    monkeypatch.setattr("simdiff.product.pipeline.simulate_finish", broken)
    code = main(["generate", "a person walks", "--length", "0.5", "--steps", "1", "--simulate", "--model",
                 str(tiny_model), "--out", str(tmp_path / "o"), "--format", "npy", "-q"])
    err = capsys.readouterr().err
    assert code != 0 and "the simulator broke (the generated motions and generation.json are written in" in err
    assert len(err.strip().splitlines()) == 1
    assert (tmp_path / "o" / "sample0_joints.npy").is_file() and not (tmp_path / "o" / "sample0_tracking.json").exists()
    assert json.loads((tmp_path / "o" / "generation.json").read_text())["simulate_error"] == "the simulator broke"


def test_generate_foot_lock_holds_planted_feet_and_keeps_the_root_path(tiny_model: Path, tmp_path: Path, capsys) -> None:
    from simdiff.motion.features import SLICES
    from simdiff.motion.rigid import joints_from_features

    import shutil

    from safetensors.torch import load_file, save_file

    model = tmp_path / "planted"  # the tiny model with every contact channel's mean at 1: its feet are planted
    shutil.copytree(tiny_model, model)
    tensors = load_file(model / "model.safetensors")
    tensors["normalizer.mean"][SLICES["contacts"]] = 1.0
    tensors["normalizer.mean"][SLICES["root_lin_vel"]] = 0.02
    save_file(tensors, model / "model.safetensors")
    argv = ["generate", "a person walks", "--length", "0.6", "--steps", "2", "--model", str(model), "--format", "npy", "-q"]
    assert main([*argv, "--out", str(tmp_path / "off")]) == 0, capsys.readouterr().err
    assert main([*argv, "--foot-lock", "1", "--out", str(tmp_path / "on")]) == 0, capsys.readouterr().err
    off, on = (np.load(tmp_path / d / "sample0_features.npy") for d in ("off", "on"))
    assert np.allclose(on, clean_feet_numpy(off), atol=1e-5)  # the feature passes
    joints_off, joints_on = (np.load(tmp_path / d / "sample0_joints.npy") for d in ("off", "on"))
    assert np.allclose(joints_on, joints_from_features(on, 1.0), atol=1e-5)  # the hold, on the written joints
    assert np.allclose(joints_on[:, 0], joints_off[:, 0], atol=1e-5)  # the root keeps its path
    assert not np.allclose(joints_on, joints_off, atol=1e-4)  # something was planted and held
    assert json.loads((tmp_path / "on" / "generation.json").read_text())["foot_lock"] == 1.0
    capsys.readouterr()
    assert main([*argv, "--foot-lock", "2", "--out", str(tmp_path / "bad")]) == 2
    err = capsys.readouterr().err
    assert "argument --foot-lock: 2 is outside [0, 1]" in err and err.count("\n") == 1


def test_generate_env_guidance_changes_only_motions_off_earth(tmp_path: Path, capsys) -> None:
    from simdiff.serve.testing import write_tiny_model

    model = write_tiny_model(tmp_path / "reacting")  # jittered weights: the adapters answer φ
    argv = ["generate", "a person jumps", "--length", "0.6", "--steps", "2", "--model", str(model),
            "--format", "npy", "-q"]

    def run(name: str, *extra: str) -> np.ndarray:
        assert main([*argv, *extra, "--out", str(tmp_path / name)]) == 0, capsys.readouterr().err
        return np.load(tmp_path / name / "sample0_features.npy")

    assert np.array_equal(run("earth1"), run("earth3", "--env-guidance", "3"))
    moon1, moon3 = run("moon1", "--gravity", "-1.6"), run("moon3", "--gravity", "-1.6", "--env-guidance", "3")
    assert not np.allclose(moon1, moon3, atol=1e-4)
    assert json.loads((tmp_path / "moon3" / "generation.json").read_text())["env_guidance"] == 3.0
    assert json.loads((tmp_path / "moon1" / "generation.json").read_text())["env_guidance"] == 1.0
    (model / "sampling.json").write_text('{"env_guidance": 3}')
    assert np.array_equal(run("stored", "--gravity", "-1.6"), moon3)  # sampling.json's value, unless given
    assert np.array_equal(run("given", "--gravity", "-1.6", "--env-guidance", "1"), moon1)
    assert main([*argv, "--env-guidance", "-1", "--out", str(tmp_path / "bad")]) == 2
    err = capsys.readouterr().err
    assert "argument --env-guidance: -1 is outside [0, 10]" in err and err.count("\n") == 1


def test_generate_env_guidance_on_a_backbone_is_one_line(tmp_path: Path, capsys) -> None:
    model = save_tiny(tmp_path / "backbone", sim=False)
    code = main(["generate", "a person walks", "--length", "0.5", "--steps", "1", "--model", str(model),
                 "--env-guidance", "2", "--format", "npy", "--out", str(tmp_path / "o"), "-q"])
    err = capsys.readouterr().err
    assert code == 2 and "--env-guidance needs a SimDiff model with a continuous Sim Encoder" in err
    assert err.count("\n") == 1


def standing_mean(lift: float) -> torch.Tensor:
    """(263,) feature mean of a still standing pose (synthetic walk, frame 0; lowest joint 0.021 m) raised by
    ``lift`` metres: with a tiny std every sample is that pose."""
    from simdiff.motion import synthetic

    pose = synthetic.walk(2)[0].astype(np.float64)
    mean = torch.zeros(263)
    mean[3] = float(pose[0, 1] + lift)  # root height
    rel = pose[1:] - pose[0] * np.array([1.0, 0.0, 1.0])  # ric: x, z relative to the root, y absolute
    rel[:, 1] += lift
    mean[4:67] = torch.as_tensor(rel.reshape(-1), dtype=torch.float32)
    return mean


def test_a_sample_that_never_touches_the_floor_is_warned_about(tmp_path: Path, capsys) -> None:
    torch.manual_seed(0)
    config = ModelConfig(backbone=backbone_preset("tiny"), sim=SimConfig())
    mean = standing_mean(lift=1.2)  # a standing pose, its feet 1.2 m up
    MotionGenerator(build_network(config), config, mean=mean, std=torch.full((263,), 0.01)).save(tmp_path / "m")
    code = main(["generate", "a person runs", "--length", "0.5", "--steps", "1", "--model", str(tmp_path / "m"),
                 "--out", str(tmp_path / "o"), "--format", "npy", "-q"])
    err = capsys.readouterr().err
    assert code == 0
    assert err.startswith("simdiff: warning: sample 0 never comes within 0.10 m of the floor (lowest joint 1.2")
    assert len(err.strip().splitlines()) == 1
    rec = json.loads((tmp_path / "o" / "generation.json").read_text())["samples"][0]
    assert rec["touches_floor"] is False and 1.1 < rec["lowest_m"] < 1.3 and rec["glides"] is False
    # the foot cleanup (cleanup 3) drops such a sample onto the floor: no warning, lowest joint at y = 0
    code = main(["generate", "a person runs", "--length", "0.5", "--steps", "1", "--model", str(tmp_path / "m"),
                 "--out", str(tmp_path / "o2"), "--format", "npy", "-q", "--foot-lock", "1"])
    assert code == 0 and capsys.readouterr().err == ""
    rec = json.loads((tmp_path / "o2" / "generation.json").read_text())["samples"][0]
    assert rec["touches_floor"] is True and abs(rec["lowest_m"]) < 0.01  # on the floor, up to the rigid fit


def test_a_gliding_sample_is_warned_about(tmp_path: Path, capsys) -> None:
    torch.manual_seed(0)
    config = ModelConfig(backbone=backbone_preset("tiny"), sim=SimConfig())
    mean = standing_mean(lift=0.05 - 0.021)  # a statue whose feet stay 5 cm above the floor
    mean[1] = 0.1  # root forward velocity 0.1 m/frame = 2 m/s
    MotionGenerator(build_network(config), config, mean=mean, std=torch.full((263,), 1e-4)).save(tmp_path / "m")
    code = main(["generate", "a person runs", "--length", "1", "--steps", "1", "--model", str(tmp_path / "m"),
                 "--out", str(tmp_path / "o"), "--format", "npy", "-q"])
    err = capsys.readouterr().err
    assert code == 0 and err.startswith("simdiff: warning: sample 0 glides: it travels while no foot lifts 0.05 m")
    assert len(err.strip().splitlines()) == 1
    assert json.loads((tmp_path / "o" / "generation.json").read_text())["samples"][0]["glides"] is True


def test_generate_reports_an_extrapolated_backbone(tmp_path: Path, capsys) -> None:
    model = save_tiny(tmp_path / "m")
    argv = ["generate", "a person waves", "--length", "0.5", "--steps", "2", "--model", str(model),
            "--format", "npy", "-q"]
    assert main([*argv, "--out", str(tmp_path / "o")]) == 0, capsys.readouterr().err
    assert "extrapolation" not in json.loads((tmp_path / "o" / "generation.json").read_text())["model"]
    (model / "extrapolation.json").write_text(json.dumps({"lambda": 1.5, "parent": "p"}))
    assert main([*argv, "--out", str(tmp_path / "x")]) == 0, capsys.readouterr().err
    meta = json.loads((tmp_path / "x" / "generation.json").read_text())["model"]
    assert meta["extrapolation"] == {"lambda": 1.5, "parent": "p"}
    (model / "extrapolation.json").write_text("{oops")  # malformed: one line, before any sampling
    capsys.readouterr()  # the good runs' own warnings (the tiny model's sample may glide)
    assert main([*argv, "--out", str(tmp_path / "bad")]) == 2
    err = capsys.readouterr().err
    assert "extrapolation.json: not valid JSON" in err and err.count("\n") == 1
    assert not (tmp_path / "bad" / "generation.json").exists()


def test_generate_edit_t_from_the_option_or_sampling_json(tmp_path: Path, capsys) -> None:
    from simdiff.serve.testing import write_tiny_model

    model = write_tiny_model(tmp_path / "editing")
    argv = ["generate", "a person jumps", "--length", "0.6", "--steps", "2", "--model", str(model),
            "--format", "npy", "-q", "--alpha", "0.5"]

    def run(name: str, *extra: str) -> np.ndarray:
        assert main([*argv, *extra, "--out", str(tmp_path / name)]) == 0, capsys.readouterr().err
        return np.load(tmp_path / name / "sample0_features.npy")

    def meta(name: str) -> dict:
        return json.loads((tmp_path / name / "generation.json").read_text())

    earth = run("earth")
    assert np.array_equal(earth, run("a0", "--alpha", "0"))  # Earth without wind: the backbone alone
    assert meta("earth")["edit_t"] == 950
    # DDIM 2 runs t 500 and 0: edit t 100 keeps the first step at Earth, edit t 600 runs both under φ
    late, early = (run(n, "--edit-t", t, "--gravity", "-1.6") for n, t in (("late", "100"), ("early", "600")))
    assert meta("late")["edit_t"] == 100 and not np.allclose(late, early, atol=1e-4)
    assert not np.allclose(late, earth, atol=1e-4)  # the last step ran under φ
    (model / "sampling.json").write_text('{"edit_t": 100}')
    assert np.array_equal(run("stored", "--gravity", "-1.6"), late)
    assert meta("stored")["edit_t"] == 100
    (model / "sampling.json").write_text('{"anchor": "edit"}')
    assert main([*argv, "--out", str(tmp_path / "bad")]) == 2
    err = capsys.readouterr().err
    assert "unknown key 'anchor' = 'edit'" in err and err.count("\n") == 1
    (model / "sampling.json").unlink()
    assert main([*argv, "--edit-t", "1000", "--out", str(tmp_path / "bad2")]) == 2
    err = capsys.readouterr().err
    assert "argument --edit-t: 1000 is outside 0..999" in err and err.count("\n") == 1


def test_generate_eta_from_the_option_or_sampling_json(tmp_path: Path, capsys) -> None:
    from simdiff.serve.testing import write_tiny_model

    model = write_tiny_model(tmp_path / "eta")
    argv = ["generate", "a person jumps", "--length", "0.6", "--steps", "3", "--model", str(model),
            "--format", "npy", "-q"]

    def run(name: str, *extra: str) -> np.ndarray:
        assert main([*argv, *extra, "--out", str(tmp_path / name)]) == 0, capsys.readouterr().err
        return np.load(tmp_path / name / "sample0_features.npy")

    def meta(name: str) -> dict:
        return json.loads((tmp_path / name / "generation.json").read_text())

    plain, zero, noisy = run("plain"), run("zero", "--eta", "0"), run("noisy", "--eta", "1")
    assert np.array_equal(plain, zero) and meta("plain")["eta"] == 0.0
    assert not np.allclose(noisy, plain, atol=1e-4) and meta("noisy")["eta"] == 1.0
    assert np.array_equal(run("again", "--eta", "1"), noisy)  # fresh noise, drawn from the seed
    (model / "sampling.json").write_text('{"eta": 1.0}')
    assert np.array_equal(run("stored"), noisy) and meta("stored")["eta"] == 1.0
    assert np.array_equal(run("told", "--eta", "0"), plain)  # the option wins
    assert main([*argv, "--sampler", "ddpm", "--out", str(tmp_path / "ddpm")]) == 0
    assert meta("ddpm")["eta"] == 0.0  # the stored η belongs to DDIM
    (model / "sampling.json").unlink()
    for extra, message in ((("--eta", "1.5"), "argument --eta: 1.5 is outside [0, 1]"),
                           (("--eta", "nan"), "argument --eta: 'nan' is not a finite number"),
                           (("--eta", "0.5", "--sampler", "ddpm"), "--eta 0.5 is DDIM's noise scale; it needs "
                                                                  "--sampler ddim, not 'ddpm'")):
        assert main([*argv, *extra, "--out", str(tmp_path / "bad")]) == 2
        err = capsys.readouterr().err
        assert message in err and err.count("\n") == 1, err
    (model / "sampling.json").write_text('{"eta": 2}')
    assert main([*argv, "--out", str(tmp_path / "bad_stored")]) == 2
    err = capsys.readouterr().err
    assert "eta must be in [0, 1], got 2" in err and err.count("\n") == 1, err
