"""The paper's experiments end to end on tiny random models, a tiny corpus and a fake simulator."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from simdiff.errors import SimdiffError
from simdiff.eval.experiments import load_config, plan_experiment, run_all, run_experiment
from simdiff.eval.experiments.config import parse_assignment
from simdiff.eval.experiments.fig5 import motion_stats
from simdiff.eval.experiments.runner import Runner
from simdiff.eval.experiments.table2 import select_alpha
from simdiff.eval.experiments.testing import EchoProjector, write_tiny_setup
from simdiff.motion.synthetic import jump, walk
from simdiff.text.base import text_dim
from simdiff.train.testing import HashTextEncoder

CONFIGS = Path(__file__).resolve().parents[1] / "configs"
PROTO = {"replications": 2, "batch_size": 8, "samples_limit": 0, "diversity_times": 8, "mm_prompts": 2, "mm_repeats": 2,
         "mm_times": 1, "seed": 0}
FAST = {"steps": 2, "ddpm_steps": 5}
PHYS = {"project_at": [500, 0]}  # steps of both DDIM-2 and DDPM-5


def hash_text(name: str) -> HashTextEncoder:
    """The injected stand-in for each model's own text encoder (right size, no weights)."""
    return HashTextEncoder(text_dim(name))


@pytest.fixture(autouse=True, scope="module")
def one_thread():
    """One torch thread: on a busy 2-core machine two spinning threads make tiny models ~25× slower."""
    import torch

    before = torch.get_num_threads()
    torch.set_num_threads(1)
    yield
    torch.set_num_threads(before)


@pytest.fixture(scope="module")
def setup(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    root = tmp_path_factory.mktemp("experiments")
    return {**write_tiny_setup(root), "root": root}


def write(setup: dict[str, Path], kind: str, name: str | None = None, **extra) -> Path:
    """A config of ``kind`` over the tiny setup (tiny protocol; run it with ``text_encoder=hash_text``)."""
    models = extra.pop("models", None) or {
        "table1": [{"name": "MDM", "model": "backbone", **FAST}, {"name": "PhysDiff", "model": "backbone", "physdiff": PHYS, **FAST},
                   {"name": "SimDiff", "model": "adapters_binary", "env_index": 1, **FAST}],
        "table2": [{"name": "SimDiff", "model": "adapters_binary", "env_index": 1, **FAST}],
        "fig4": [{"name": "MDM", "model": "backbone", **FAST}, {"name": "PhysDiff", "model": "backbone", "physdiff": PHYS, **FAST},
                 {"name": "SimDiff", "model": "adapters", **FAST}],
        "fig5": [{"name": "MDM", "model": "backbone", **FAST}, {"name": "SimDiff", "model": "adapters", **FAST}],
        "env_response": [{"name": "MDM", "model": "backbone", **FAST}],
        "contacts": [{"name": "MDM", "model": "backbone", **FAST}],
        "editing": [{"name": "SimDiff", "model": "adapters", **FAST}],
        "following": [{"name": "SimDiff", "model": "adapters", **FAST}],
        "retrack": [{"name": "MDM", "model": "backbone", **FAST}, {"name": "PhysDiff", "model": "backbone", "physdiff": PHYS, **FAST},
                    {"name": "SimDiff", "model": "adapters", **FAST}],
    }[kind]
    cfg = {"name": name or kind, "kind": kind, "corpus": str(setup["corpus"]),
           "paths": {r: str(setup[r]) for r in ("backbone", "adapters", "adapters_binary")},
           "evaluator": {"kind": "ours", "path": str(setup["evaluator"])}, "protocol": PROTO, "models": models,
           "out_dir": str(setup["root"] / "reports"), "smoke": True, **extra}
    path = setup["root"] / f"eval_{name or kind}.json"
    path.write_text(json.dumps(cfg))
    return path


def test_shipped_configs_are_the_experiments_with_relative_paths() -> None:
    paths = sorted(CONFIGS.glob("eval_*.json"))
    assert [p.stem for p in paths] == ["eval_contacts", "eval_editing", "eval_env_response", "eval_fig4", "eval_fig5",
                                       "eval_following", "eval_heldout", "eval_retrack", "eval_table1", "eval_table2"]
    for path in paths:
        raw = json.loads(path.read_text())
        assert raw["kind"] == raw["name"] == path.stem[5:]
        for value in [raw["corpus"], *([raw["evaluator"]["path"]] if "evaluator" in raw else []), *raw["paths"].values()]:
            assert not Path(value).is_absolute() and "/tmp" not in value, value
        quick = load_config(path, "quick")
        full = load_config(path, "full")
        assert quick.budgets["quick"]["about"] and quick.budget == "quick"
        assert quick != full
    t1, t2 = load_config(CONFIGS / "eval_table1.json", "quick"), load_config(CONFIGS / "eval_table2.json", "quick")
    assert t1.protocol == t2.protocol
    assert t1.samplers == ["ddim", "ddpm"] and t1.alphas == [] and t1.ddpm_samples == 4  # SimDiff at the model's α
    assert t2.alphas == [0.5, 0.925] and t2.split == "val"  # α is chosen on val, never on test
    shipped = "simdiff/assets/default_model"
    assert all(p == shipped for c in (t1, t2) for p in c.paths.values())  # the reports are the shipped model's
    assert [m.physdiff["project_at"] for m in t1.models if m.physdiff] == [[60, 40, 20, 0]]


def test_budget_and_overrides_apply_in_order(tmp_path: Path) -> None:
    path = CONFIGS / "eval_table1.json"
    c = load_config(path, "quick", [parse_assignment("protocol.replications=5"), ("paths.backbone", "/x/bb"),
                                    parse_assignment("models.0.name=Backbone")])
    assert c.protocol.replications == 5 and c.protocol.samples_limit == 0  # the override beats the budget
    assert c.paths["backbone"] == "/x/bb" and c.models[0].name == "Backbone"
    assert c.resolved_paths()["backbone"] == "/x/bb"
    assert Path(c.resolved_paths()["corpus"]).is_absolute()
    with pytest.raises(SimdiffError, match="no budget 'huge'"):
        load_config(path, "huge")
    with pytest.raises(SimdiffError, match="protocl"):
        load_config(path, None, [("protocl.replications", 3)])
    with pytest.raises(SimdiffError, match="not an index"):
        load_config(path, None, [("models.9.alpha", 3)])
    with pytest.raises(SimdiffError, match="KEY=VALUE"):
        parse_assignment("replications")
    assert parse_assignment("a.b=[1, 2]") == ("a.b", [1, 2]) and parse_assignment("x=runs/m") == ("x", "runs/m")


def test_select_alpha_rules() -> None:
    def row(alpha: float, fid: float, pen: float) -> dict:
        s = {"fid": {"mean": fid}, "penetration": {"mean": pen}, "floating": {"mean": 0.0}, "sliding": {"mean": 0.0},
             "phys_err": {"mean": pen, "ci95": 0.0}}
        return {"alpha": alpha, "method": "S", "sampler": "ddim", "summary": s}

    rows = [row(0.01, 1.0, 9.0), row(0.1, 2.0, 2.0), row(1.0, 5.0, 1.0)]
    assert select_alpha(rows, "fid")["alpha"] == 0.01
    assert select_alpha(rows, "phys_err")["alpha"] == 1.0
    assert select_alpha(rows, "balanced")["alpha"] == 0.1  # scaled (0+1)/2, (0.25+0.125)/2, (1+0)/2
    assert select_alpha([], "balanced") is None


def test_motion_stats_apex_and_drift() -> None:
    s = motion_stats(jump(60, height=0.3, start=20))  # 0.5 s up: curvature −8·0.3/0.5² = −9.6 m/s²
    assert s["apex_m"] == pytest.approx(0.3, abs=0.01) and abs(s["drift_x_m"]) < 1e-6
    assert s["gravity_read"] == pytest.approx(-9.6, rel=0.02) and s["flight_fit_mm"] < 1.0
    w = walk(41, speed=1.0)  # 2 s forward (+Z)
    s = motion_stats(w)
    assert s["drift_z_m"] == pytest.approx(2.0, abs=0.05) and abs(s["drift_x_m"]) < 0.05
    assert s["gravity_read"] is None  # no flight


def test_table2_then_table1_best_alpha_reuse_and_resume(setup: dict[str, Path], monkeypatch: pytest.MonkeyPatch) -> None:
    sim = EchoProjector()
    t2 = run_experiment(write(setup, "table2", alphas=[0.1, 1.0]), projector=sim, progress=False, command=["simdiff", "t2"], text_encoder=hash_text)
    assert [r["alpha"] for r in t2["rows"]] == [0.1, 1.0]
    assert t2["rows"][0]["summary"]["fid"]["mean"] != t2["rows"][1]["summary"]["fid"]["mean"]  # α reaches the model
    best = t2["best_alpha"]["alpha"]
    assert best in (0.1, 1.0) and (setup["root"] / "reports/table2/table2.png").is_file()

    t1_path = write(setup, "table1", samplers=["ddpm", "ddim"], alphas=[0.1, "best"], reuse_rows_from=["table2"],
                    ddpm_samples=3)
    t1 = run_experiment(t1_path, projector=sim, progress=False, command=["simdiff", "t1"], text_encoder=hash_text)
    keys = [r["key"] for r in t1["rows"]]
    expect = ["ground_truth", "MDM_ddpm", "MDM_ddim", "PhysDiff_ddpm", "PhysDiff_ddim", "SimDiff_ddpm_alpha0.1"]
    if best == 1.0:
        expect += ["SimDiff_ddpm_alpha1", "SimDiff_ddim_alpha0.1", "SimDiff_ddim_alpha1"]
    else:
        expect += ["SimDiff_ddim_alpha0.1"]
    assert sorted(keys) == sorted(expect)
    rows = {r["key"]: r for r in t1["rows"]}
    # DDPM rows: physics + time on 3 motions (fewer than a batch); DDIM rows: the full protocol with MultiModality
    assert rows["MDM_ddpm"]["measured"] == "subset" and rows["MDM_ddpm"]["samples"] == 3
    assert set(rows["MDM_ddpm"]["physics"]) == {"penetration", "floating", "sliding", "skate_ratio", "floating_to_gt",
                                                "phys_err"}
    s = rows["PhysDiff_ddim"]["summary"]
    assert {"r_precision_top1", "r_precision_top3", "fid", "mm_dist", "diversity", "multimodality", "skate_ratio"} <= set(s)
    assert s["fid"]["n"] == 2 and rows["PhysDiff_ddim"]["samples_per_replication"] == 8
    # SimDiff DDIM at 0.1 is table2's row, relabelled, not measured again
    reused = rows["SimDiff_ddim_alpha0.1"]
    assert reused["reused_from"].endswith("table2/rows/SimDiff_ddim_alpha0.1.json")
    assert reused["summary"] == t2["rows"][0]["summary"] and reused["alpha_choice"].startswith("paper")
    assert t1["best_alpha"]["alpha"] == best
    # PhysDiff projected under Earth, 2 projections per batch: DDPM 1 batch of 3, DDIM 2 reps × (1 batch + 2 MM prompts)
    assert {e for _, envs in sim.calls for e in envs} == {(-9.81, 0.0, 0.0)}
    assert len(sim.calls) == 2 * 1 + 2 * 2 * (1 + 2)
    md = (setup["root"] / "reports/table1/report.md").read_text()
    for text in ("Table 1", "git commit", "seed: 0", "budget: **full**", str(setup["backbone"]), "PhysDiff", "MModality",
                 "projection at t = 500, 0", "† physics metrics"):
        assert text in md, text
    report = json.loads((setup["root"] / "reports/table1/report.json").read_text())
    assert report["paths"]["adapters_binary"] == str(setup["adapters_binary"]) and report["provenance"]["command"] == "simdiff t1"

    # resume: nothing is measured again; a changed setting re-measures only the rows it affects
    def boom(*args, **kwargs):
        raise AssertionError("measured again")

    monkeypatch.setattr(Runner, "protocol_measure", boom)
    monkeypatch.setattr(Runner, "subset_measure", boom)
    monkeypatch.setattr(Runner, "gt_measure", boom)
    again = run_experiment(t1_path, projector=sim, progress=False, text_encoder=hash_text)
    assert [r["summary"] if "summary" in r else r["physics"] for r in again["rows"]] == \
           [r["summary"] if "summary" in r else r["physics"] for r in t1["rows"]]
    assert [p["state"] for p in plan_experiment(t1_path)] == ["cached"] * len(keys)
    changed = [p for p in plan_experiment(t1_path, overrides=[("ddpm_samples", 2)]) if p["state"] == "measure"]
    assert {p["key"] for p in changed} == {k for k in keys if "ddpm" in k}


def test_fig4_times_every_method_and_sampler(setup: dict[str, Path]) -> None:
    sim = EchoProjector()
    report = run_experiment(write(setup, "fig4", samplers=["ddpm", "ddim"],
                                  timing={"text": "a person jumps", "length": 24, "repeats": 3, "ddpm_repeats": 1, "warmup": 1}),
                            projector=sim, progress=False, text_encoder=hash_text)
    cells = {(r["method"], r["sampler"]): r for r in report["rows"]}
    assert set(cells) == {(m, s) for m in ("MDM", "PhysDiff", "SimDiff") for s in ("ddpm", "ddim")}
    assert len(cells["MDM", "ddim"]["times_s"]) == 3 and len(cells["MDM", "ddpm"]["times_s"]) == 1
    assert cells["PhysDiff", "ddim"]["projection_median_s"] is not None and cells["MDM", "ddim"]["projection_median_s"] is None
    assert len(sim.calls) == 3 * 2 + 1 * 2 and sim.calls[0][0] == [25]  # batch 1, 24 rows → 25 joint frames
    assert report["reference"]["method"] == "MDM" and report["reference"]["sampler"] == "ddim"
    md = (setup["root"] / "reports/fig4/report.md").read_text()
    assert "× reference" in md and (setup["root"] / "reports/fig4/fig4.png").is_file()


def test_fig5_sweeps_combination_and_filmstrips(setup: dict[str, Path]) -> None:
    control = {"prompts": ["a person jumps"], "seeds": 2, "length": 20, "gravity": [-1.0, -9.81], "wind": [0.0, 10.0],
               "combos": [[-3.0, 7.0, 7.0]], "alpha": 1.0, "filmstrip_frames": 2}
    report = run_experiment(write(setup, "fig5", env_control=control), progress=False, text_encoder=hash_text)
    envs = [(r["method"], r["factor"], tuple(r["env"]) if r["env"] else None) for r in report["rows"]]
    assert envs == [("MDM", "reference", None), ("SimDiff", "gravity", (-1.0, 0.0, 0.0)), ("SimDiff", "gravity", (-9.81, 0.0, 0.0)),
                    ("SimDiff", "wind_x", (-9.81, 10.0, 0.0)), ("SimDiff", "wind_y", (-9.81, 0.0, 10.0)),
                    ("SimDiff", "gravity", (-3.0, 0.0, 0.0)), ("SimDiff", "wind_x", (-9.81, 7.0, 0.0)),
                    ("SimDiff", "wind_y", (-9.81, 0.0, 7.0)), ("SimDiff", "combo", (-3.0, 7.0, 7.0))]
    apex = [r["summary"]["apex_m"]["mean"] for r in report["rows"][1:]]
    assert len(set(np.round(apex, 6))) > 1  # φ reaches the model
    assert all(len(r["samples"]) == 2 for r in report["rows"])
    out = setup["root"] / "reports/fig5"
    for name in ("fig5.png", "fig5_combination.png", "fig5_strip_gravity.png", "fig5_strip_wind.png", "fig5_strip_combo0.png"):
        assert (out / name).is_file(), name
    md = (out / "report.md").read_text()
    assert "Unseen combination φ = (-3, 7, 7)" in md and "| apex_m |" in md


def test_retrack_reports_tracked_fraction_per_method_and_env(setup: dict[str, Path]) -> None:
    sim = EchoProjector(fail_every=2)
    report = run_experiment(write(setup, "retrack", envs=[[-3.0, 0.0, 0.0]], retrack_samples=4), projector=sim, progress=False, text_encoder=hash_text)
    rows = {r["method"]: r for r in report["rows"]}
    assert set(rows) == {"Ground truth", "MDM", "PhysDiff", "SimDiff"}
    for r in rows.values():
        assert r["n"] == 4 and r["tracked"] == 2 and r["tracked_fraction"] == 0.5 and r["d_l2_mean"] == pytest.approx(1.5)
    # every re-tracking call and every PhysDiff projection ran under the row's φ
    assert {e for _, envs in sim.calls for e in envs} == {(-3.0, 0.0, 0.0)}
    assert (setup["root"] / "reports/retrack/retrack.png").is_file()


def test_run_all_only_and_missing_model(setup: dict[str, Path], tmp_path: Path) -> None:
    configs = tmp_path / "configs"
    configs.mkdir()
    mdm = [{"name": "MDM", "model": "backbone", **FAST}]
    for kind in ("table2", "fig4"):
        path = write(setup, kind, name=f"all_{kind}", alphas=[1.0], models=None if kind == "table2" else mdm,
                     timing={"length": 16, "repeats": 1, "ddpm_repeats": 1})
        (configs / f"eval_{kind}.json").write_text(path.read_text())
    logs: list[str] = []
    reports = run_all(configs, only=["fig4", "table2"], overrides=[("samplers", ["ddim"])], projector=EchoProjector(),
                      progress=False, log=logs.append, text_encoder=hash_text)
    assert [r["kind"] for r in reports] == ["table2", "fig4"]  # dependency order, not the order asked
    assert "estimated" in logs[0] and len(logs) == 4
    with pytest.raises(SimdiffError, match="unknown experiment 'fig9'"):
        run_all(configs, only=["fig9"])
    with pytest.raises(SimdiffError, match=r"no model.safetensors \(set it with --backbone DIR\)"):
        run_experiment(write(setup, "fig4", name="missing"), overrides=[("paths.backbone", str(tmp_path / "none"))],
                       projector=EchoProjector(), progress=False)


def test_cli_dry_run_and_one_line_errors(setup: dict[str, Path], capsys: pytest.CaptureFixture[str]) -> None:
    from simdiff.cli.main import main

    path = write(setup, "table2", name="cli_table2", alphas=[0.2])
    assert main(["evaluate", "run", str(path), "--dry-run", "--set", "protocol.replications=4"]) == 0
    out = capsys.readouterr().out
    assert "SimDiff_ddim_alpha0.2" in out and "measure" in out and "estimated" in out
    assert main(["evaluate", "run", str(path), "--set", "protocol.replications"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("simdiff: error:") and "KEY=VALUE" in err and "\n" not in err
    assert main(["evaluate", "run", str(CONFIGS / "eval_table1.json"), "--budget", "quick", "--corpus", str(setup["corpus"]),
                 "--evaluator", str(setup["evaluator"]), "--backbone", str(setup["root"] / "nowhere"),
                 "--out-dir", str(setup["root"] / "cli_reports")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("simdiff: error: model folder") and "--backbone DIR" in err and err.count("\n") == 1
    assert main(["evaluate", "run", str(CONFIGS / "eval_table1.json"), "--corpus", str(setup["root"] / "no_corpus"),
                 "--out-dir", str(setup["root"] / "cli_reports")]) == 2
    assert "--corpus DIR" in capsys.readouterr().err


def test_table1_uses_the_best_alpha_known_when_it_started(setup: dict[str, Path], tmp_path: Path) -> None:
    from simdiff.eval.experiments import table1

    config = load_config(write(setup, "table1", name="t1_best", alphas=[0.1, "best"]), None,
                         [("out_dir", str(tmp_path)), ("samplers", ["ddim"])])
    runner = Runner(config, progress=False)
    keys = [p.key for p in table1.plan(runner)]
    assert keys == ["ground_truth", "MDM_ddim", "PhysDiff_ddim", "SimDiff_ddim_alpha0.1"]
    (tmp_path / "table2").mkdir()
    (tmp_path / "table2" / "report.json").write_text(json.dumps({"best_alpha": {"alpha": 0.5, "select_by": "balanced"}}))
    value, source = table1.best_alpha(runner)  # the report appeared mid-run: this run keeps what it planned with
    assert value is None and "run table2 first" in source
    assert [p.key for p in table1.plan(Runner(config, progress=False))][-1] == "SimDiff_ddim_alpha0.5"


def test_a_method_may_list_its_own_alphas_in_table1(setup: dict[str, Path], tmp_path: Path) -> None:
    """The simulated finish at the shipped α only, while the plain SimDiff rows take the table's α list."""
    from simdiff.eval.experiments import table1

    finish = {"name": "SimDiff + simulated finish", "model": "adapters_binary", "env_index": 1, "simulate": True,
              "alphas": [1.0]}
    plain = {"name": "SimDiff", "model": "adapters_binary", "env_index": 1}
    config = load_config(write(setup, "table1", name="t1_own", alphas=[0.1, "best"], models=[finish, plain]), None,
                         [("out_dir", str(tmp_path)), ("samplers", ["ddim"]), ("best_alpha", 0.5)])
    keys = [p.key for p in table1.plan(Runner(config, progress=False))]
    assert keys == ["ground_truth", "SimDiff___simulated_finish_ddim_alpha1", "SimDiff_ddim_alpha0.1", "SimDiff_ddim_alpha0.5"]


def test_a_backbone_role_on_a_simdiff_folder_runs_its_backbone_alone(setup: dict[str, Path], tmp_path: Path) -> None:
    """`--backbone simdiff/assets/default_model` (a SimDiff folder): the MDM and PhysDiff rows must be the frozen
    backbone, φ-blind, one row (no α list), generating exactly what `train export-backbone`'s folder generates."""
    import torch

    from simdiff.eval.experiments import table1
    from simdiff.model.checkpoint import export_backbone

    exported = export_backbone(setup["adapters"], tmp_path / "exported")
    models = [{"name": "MDM", "model": "backbone", **FAST}, {"name": "PhysDiff", "model": "backbone", "physdiff": PHYS, **FAST},
              {"name": "SimDiff", "model": "adapters", **FAST}]
    config = load_config(write(setup, "table1", name="t1_bb", models=models), None,
                         [("out_dir", str(tmp_path)), ("samplers", ["ddim"]), ("alphas", [0.5, 1.0]),
                          ("paths.backbone", str(setup["adapters"]))])
    runner = Runner(config, progress=False, text_encoder=hash_text)
    mdm, physdiff, simdiff = config.models
    keys = [p.key for p in table1.plan(runner)]
    assert keys == ["ground_truth", "MDM_ddim", "PhysDiff_ddim", "SimDiff_ddim_alpha0.5", "SimDiff_ddim_alpha1"]
    assert runner.sim_mode(mdm) is None and runner.sim_mode(physdiff) is None and runner.sim_mode(simdiff) == "continuous"
    assert not runner.model(mdm).is_simdiff and runner.model(simdiff).is_simdiff
    assert runner.method_inputs(mdm, "ddim", None)["backbone_only"] is True
    assert "backbone_only" not in runner.method_inputs(simdiff, "ddim", 0.5)
    lengths = np.array([40, 40])
    got = runner.generate_fn(mdm, "ddim", env=(-1.6, 5.0, 0.0))(["a person jumps", "a person walks"], lengths, 3)
    plain = load_config(write(setup, "table1", name="t1_exp", models=models[:1]), None,
                        [("out_dir", str(tmp_path)), ("paths.backbone", str(exported))])
    ref_runner = Runner(plain, progress=False, text_encoder=hash_text)
    want = ref_runner.generate_fn(plain.models[0], "ddim")(["a person jumps", "a person walks"], lengths, 3)
    torch.testing.assert_close(torch.as_tensor(np.asarray(got)), torch.as_tensor(np.asarray(want)))
    adapters = runner.generate_fn(simdiff, "ddim", alpha=1.0, env=(-1.6, 5.0, 0.0))(["a person jumps", "a person walks"],
                                                                                   lengths, 3)
    assert not np.allclose(np.asarray(adapters), np.asarray(got))


def test_a_method_may_list_its_own_samplers(setup: dict[str, Path], tmp_path: Path) -> None:
    """DDPM rows for MDM and SimDiff at α = 1 only; the binary model and the finish stay DDIM-only."""
    from simdiff.eval.experiments import table1

    mdm = {"name": "MDM", "model": "backbone"}
    finish = {"name": "SimDiff + simulated finish", "model": "adapters_binary", "env_index": 1, "simulate": True,
              "alphas": [1.0], "samplers": ["ddim"]}
    ddim = {"name": "SimDiff", "model": "adapters_binary", "env_index": 1, "samplers": ["ddim"]}
    ddpm = {"name": "SimDiff", "model": "adapters_binary", "env_index": 1, "samplers": ["ddpm"], "alphas": [1.0]}
    config = load_config(write(setup, "table1", name="t1_samplers", alphas=[1.0, "best"], models=[mdm, finish, ddim, ddpm]),
                         None, [("out_dir", str(tmp_path)), ("samplers", ["ddim", "ddpm"]), ("best_alpha", 0.1)])
    keys = [p.key for p in table1.plan(Runner(config, progress=False))]
    assert keys == ["ground_truth", "MDM_ddim", "MDM_ddpm", "SimDiff___simulated_finish_ddim_alpha1", "SimDiff_ddim_alpha1",
                    "SimDiff_ddim_alpha0.1", "SimDiff_ddpm_alpha1"]
    with pytest.raises(SimdiffError, match="model 'MDM' sampler 'ddpm' is not one of the table's samplers"):
        load_config(write(setup, "table1", name="t1_bad_sampler", models=[{**mdm, "samplers": ["ddpm"]}]), None,
                    [("samplers", ["ddim"])])


def test_config_refuses_a_text_encoder_stand_in(setup: dict[str, Path]) -> None:
    with pytest.raises(SimdiffError, match="text_encoder 'hash' must be \"auto\""):
        load_config(write(setup, "fig4", name="hash_encoder", text_encoder="hash"))


class PhysicsStandIn:
    """A fake simulator with a known response: wind pushes the body 0.02 m/s per N, low gravity lifts it mid-motion."""

    def __init__(self) -> None:
        self.envs: list[tuple[float, float, float]] = []

    def __call__(self, motions, envs):
        for m, e in zip(motions, envs):
            g, wx, wy = e.as_tuple()
            self.envs.append((g, wx, wy))
            out = np.array(m, dtype=np.float32)
            t = np.arange(len(out))[:, None] / 20.0
            out[..., 0] += 0.02 * wx * t
            out[..., 2] += 0.02 * wy * t
            bump = np.sin(np.linspace(0, np.pi, len(out))) * 0.1 * (9.81 / abs(g) - 1.0)
            out[..., 1] += bump[:, None]
            yield out, {"success": True, "status": "ok"}


def test_env_response_scores_methods_against_the_simulator(setup: dict[str, Path]) -> None:
    sim = PhysicsStandIn()
    control = {"prompts": ["a person jumps", "a person walks"], "seeds": 2, "length": 24, "gravity": [-3.0],
               "wind": [5.0], "combos": [[-3.0, 5.0, 0.0]], "resamples": 50}
    models = [{"name": "MDM", "model": "backbone", **FAST}, {"name": "SimDiff", "model": "adapters", **FAST},
              {"name": "SimDiff binary", "model": "adapters_binary", "env_index": 1, **FAST}]
    report = run_experiment(write(setup, "env_response", env_control=control, models=models), projector=sim,
                            progress=False, text_encoder=hash_text)
    rows = {r["method"]: r for r in report["rows"]}
    grid = [(-9.81, 0.0, 0.0), (-3.0, 0.0, 0.0), (-9.81, 5.0, 0.0), (-9.81, 0.0, 5.0), (-3.0, 5.0, 0.0)]
    assert [tuple(e) for e in rows["MDM"]["envs"]] == grid
    assert set(sim.envs) == set(grid) and len(sim.envs) == 3 * 4 * len(grid)  # 3 methods × 4 units × every φ
    mdm = {(s["factor"], s["quantity"]): s for s in rows["MDM"]["scores"]}
    assert not rows["MDM"]["env_aware"] and rows["SimDiff"]["env_aware"]
    # binary adapters take a class, not φ: one generation for every φ, so no response, as MDM
    assert not rows["SimDiff binary"]["env_aware"]
    binary = {(s["factor"], s["quantity"]): s for s in rows["SimDiff binary"]["scores"]}
    assert binary[("wind", "drift_along_wind_m")]["slope_ratio"][0] == pytest.approx(0.0, abs=1e-9)
    # the simulator's answer is known: +0.2 m along the wind over 1.15 s at 5 N... and MDM does not respond at all
    drift = mdm[("wind", "drift_along_wind_m")]
    assert drift["mean_dsim"] == pytest.approx(0.02 * 5 * 23 / 20, abs=1e-3) and drift["n_units"] == 4
    assert drift["slope_ratio"][0] == pytest.approx(0.0, abs=1e-9) and drift["sign_agreement"][0] == 0.0
    assert mdm[("gravity", "apex_m")]["mean_dsim"] > 0.1 and mdm[("gravity", "apex_m")]["slope_ratio"][0] == pytest.approx(0.0, abs=1e-9)
    # the simulated effects are additive by construction here
    add = {a["quantity"]: a for a in rows["MDM"]["additivity"]}
    assert add["drift_x_m"]["simulated"][0] == pytest.approx(0.0, abs=1e-4) and add["drift_x_m"]["generated"][0] == 0.0
    md = (setup["root"] / "reports/env_response/report.md").read_text()
    assert "slope ratio" in md and "Additivity" in md and "no (one generation for every φ)" in md
    assert (setup["root"] / "reports/env_response/env_response.png").is_file()


class BallisticStandIn:
    """A simulator whose rollout of any motion is a synthetic jump whose flight obeys the requested gravity."""

    def __call__(self, motions, envs):
        from simdiff.motion.synthetic import jump

        for env in envs:
            airtime = float(np.sqrt(8 * 0.4 / abs(env.gravity)))
            yield jump(frames=int(airtime * 20) + 40, height=0.4, start=15, airtime=airtime), {"success": True}


def test_env_response_checks_the_gravity_readout_on_real_jumps(setup: dict[str, Path]) -> None:
    from simdiff.motion.synthetic import jump

    corpus = setup["corpus"]
    test = sorted((corpus / "test.txt").read_text().split())
    saved = {i: np.load(corpus / "new_joints" / f"{i}.npy") for i in test[:2]}
    for i in saved:  # two real "jumps" of the split with an Earth flight
        np.save(corpus / "new_joints" / f"{i}.npy", jump(frames=60, height=0.3, start=15,
                                                           airtime=float(np.sqrt(8 * 0.3 / 9.81))).astype(np.float32))
    clips = [{"id": i, "motion_type": "jump" if i in saved else "walk", "mirror_of": None, "captions": ["x"],
              "split": "test" if i in test else "train"}
             for i in sorted(p.stem for p in (corpus / "new_joints").glob("*.npy"))]
    (corpus / "manifest.json").write_text(json.dumps({"clips": clips}))
    control = {"prompts": ["a person jumps"], "seeds": 1, "length": 24, "gravity": [-1.6], "wind": [], "combos": [],
               "resamples": 20, "readout_clips": 3}
    try:
        report = run_experiment(write(setup, "env_response", name="env_readout", env_control=control,
                                      models=[{"name": "MDM", "model": "backbone", **FAST}]),
                                projector=BallisticStandIn(), progress=False, text_encoder=hash_text)
    finally:
        (corpus / "manifest.json").unlink()
        for i, joints in saved.items():
            np.save(corpus / "new_joints" / f"{i}.npy", joints)
    check = next(r for r in report["rows"] if r.get("part") == "readout")
    assert len(check["clips"]) == 2 and check["real"]["read"] == 2
    assert check["real"]["median"] == pytest.approx(-9.81, rel=0.05)
    assert [s["gravity"] for s in check["simulated"]] == [-9.81, -1.6]
    assert all(s["read"] == 2 and s["within_10pct"] == 1.0 for s in check["simulated"])
    md = (setup["root"] / "reports/env_readout/report.md").read_text()
    assert "Readout check" in md and "| simulated | -1.6 | 2 / 2 |" in md


def test_simulated_finish_rows_in_table1_and_fig4(setup: dict[str, Path]) -> None:
    sim = EchoProjector(fail_every=4)
    finish = {"name": "SimDiff + simulated finish", "model": "adapters_binary", "env_index": 1, "simulate": True, **FAST}
    report = run_experiment(write(setup, "table1", name="t1_sim", samplers=["ddim"], alphas=[0.1], models=[finish]),
                            projector=sim, progress=False, text_encoder=hash_text)
    row = next(r for r in report["rows"] if r["method"] == "SimDiff + simulated finish")
    assert row["measured"] == "protocol" and "phys_err" in row["summary"]
    # every finished sample is counted; the fake falls on samples 0, 4, 8, ... of each call
    sizes = [n for frames, _ in sim.calls for n in [len(frames)]]
    falls = sum(len(range(0, n, 4)) for n in sizes)
    assert row["finish"] == {"motions": sum(sizes), "tracked": sum(sizes) - falls,
                             "tracked_frac": pytest.approx((sum(sizes) - falls) / sum(sizes)),
                             "second_tries": falls, "fallback_kept": 0}
    # one re-tracking per generated batch: 2 replications × 1 batch + 2 MultiModality prompts each, under Earth
    assert len(sim.calls) == 2 * (1 + 2) and {e for _, envs in sim.calls for e in envs} == {(-9.81, 0.0, 0.0)}
    md = (setup["root"] / "reports/t1_sim/report.md").read_text()
    assert "SimDiff + simulated finish" in md and "Student-t" in md and "|floating − ground truth's floating|" in md
    assert f"the simulator tracked {sum(sizes) - falls} of {sum(sizes)} final samples to the end" in md
    assert f"{falls} had a second try under the slip guard" in md
    timing = {"text": "a person jumps", "length": 24, "repeats": 2, "ddpm_repeats": 1, "warmup": 0}
    fig = run_experiment(write(setup, "fig4", name="f4_sim", samplers=["ddim"], timing=timing,
                               models=[{"name": "MDM", "model": "backbone", **FAST}, finish]),
                         projector=sim, progress=False, text_encoder=hash_text)
    cell = next(r for r in fig["rows"] if r["method"] == "SimDiff + simulated finish")
    assert cell["projection_median_s"] is not None and len(cell["times_s"]) == 2
    assert sim.calls[-1][0] == [24]  # the final sample's joints, once per repeat


def test_the_simulated_finish_anchors_planted_feet_and_physdiff_does_not(setup: dict[str, Path]) -> None:
    """One tracker for PhysDiff and re-tracking (the augmentation's), the finish's with anchored stance feet."""
    from simdiff.eval.experiments.config import load_config
    from simdiff.eval.experiments.runner import Runner

    runner = Runner(load_config(write(setup, "table1", name="t1_anchor")))
    try:
        from simdiff.sim.tracker import FINISH_LATE_FOOT, FINISH_LEAD

        assert runner.sim._pool.cfg.retarget.anchor_stance is False
        assert runner.finish_sim._pool.cfg.retarget.anchor_stance is True
        assert runner.sim._pool.cfg.tracker_config is None  # PhysDiff and re-tracking: the augmentation's tracker
        assert runner.finish_sim._pool.cfg.tracker_config.lead == FINISH_LEAD
        assert runner.finish_sim._pool.cfg.tracker_config.balance.moving_kp_xy == 0.0
        assert runner.finish_sim._pool.cfg.tracker_config.balance.late_foot == FINISH_LATE_FOOT != "release"
        assert runner.serial_projector(anchor_stance=True)._pool.cfg.retarget.anchor_stance is True
    finally:
        runner.close()
    injected = EchoProjector()
    assert Runner(load_config(write(setup, "table1", name="t1_inj")), projector=injected).finish_sim is injected


def test_env_response_row_with_env_guidance(setup: dict[str, Path]) -> None:
    control = {"prompts": ["a person jumps"], "seeds": 2, "length": 24, "gravity": [-3.0], "wind": [5.0], "combos": [],
               "resamples": 50}
    models = [{"name": "SimDiff", "model": "adapters", **FAST},
              {"name": "SimDiff eg3", "model": "adapters", "env_guidance": 3.0, **FAST}]
    report = run_experiment(write(setup, "env_response", name="env_eg", env_control=control, models=models),
                            projector=PhysicsStandIn(), progress=False, text_encoder=hash_text)
    rows = {r["method"]: r for r in report["rows"]}

    def gen(row: dict, env: tuple) -> list:
        return [r["gen"] for r in row["records"] if tuple(r["env"]) == env]

    earth, low = (-9.81, 0.0, 0.0), (-3.0, 0.0, 0.0)
    assert gen(rows["SimDiff"], earth) == gen(rows["SimDiff eg3"], earth)  # Earth motions: unchanged
    assert gen(rows["SimDiff"], low) != gen(rows["SimDiff eg3"], low)
    bad = [{"name": "MDM", "model": "backbone", "env_guidance": 2.0, **FAST}]
    with pytest.raises(SimdiffError, match="env_guidance 2 needs continuous SimDiff adapters"):
        run_experiment(write(setup, "env_response", name="env_bad", env_control=control, models=bad),
                       projector=PhysicsStandIn(), progress=False, text_encoder=hash_text)
    neg = [{"name": "SimDiff", "model": "adapters", "env_guidance": -1, **FAST}]
    with pytest.raises(SimdiffError, match="env_guidance must be a finite number ≥ 0, got -1"):
        run_experiment(write(setup, "env_response", name="env_neg", env_control=control, models=neg),
                       projector=PhysicsStandIn(), progress=False, text_encoder=hash_text)


def test_contacts_reports_each_type_with_and_without_cleanup_against_real_clips(setup: dict[str, Path]) -> None:
    corpus = setup["corpus"]
    ids = sorted(p.stem for p in (corpus / "new_joints").glob("*.npy"))
    test = set((corpus / "test.txt").read_text().split())
    clips = [{"id": i, "motion_type": "jump" if int(i) % 3 == 2 else "walk", "mirror_of": None,
              "split": "test" if i in test else "train"} for i in ids]
    (corpus / "manifest.json").write_text(json.dumps({"clips": clips}))
    try:
        options = {"prompts": {"walk": ["a person walks"], "jump": ["a person jumps"]}, "seeds": 2, "length": 30}
        report = run_experiment(write(setup, "contacts", contacts=options), progress=False, text_encoder=hash_text)
    finally:
        (corpus / "manifest.json").unlink()
    rows = {(r["method"], r["type"]): r for r in report["rows"]}
    assert set(rows) == {("real mocap", "walk"), ("real mocap", "jump"), ("MDM", "walk"), ("MDM", "jump")}
    real = rows[("real mocap", "walk")]
    assert real["real"]["n"] == sum(1 for c in clips if c["split"] == "test" and c["motion_type"] == "walk")
    assert real["real"]["bone_std_mm"]["max"] < 0.1 and real["real"]["above_speed_limit"] == 0.0  # the corpus is its own limit
    model = rows[("MDM", "walk")]
    assert model["without"]["n"] == model["with"]["n"] == 2
    assert model["with"]["bone_std_mm"]["max"] < 1.0 and model["without"]["bone_std_mm"]["max"] < 1.0  # rigid written joints
    md = (setup["root"] / "reports/contacts/report.md").read_text()
    assert "| walk | real (test" in md and "| jump | MDM, no cleanup |" in md


def test_editing_reports_replays_keyframes_and_a_timeline(setup: dict[str, Path]) -> None:
    corpus = setup["corpus"]
    ids = sorted(p.stem for p in (corpus / "new_joints").glob("*.npy"))
    test = set((corpus / "test.txt").read_text().split())
    clips = [{"id": i, "motion_type": "jump" if int(i) % 3 == 2 else "walk", "mirror_of": None, "captions": ["x"],
              "split": "test" if i in test else "train"} for i in ids]
    (corpus / "manifest.json").write_text(json.dumps({"clips": clips}))
    options = {"replay_clips": 1, "gravity": [-1.6], "seeds": 1, "keyframe_clips": 1, "keyframe_frames": 30,
               "keep": {"lower": "a person waves", "upper": "a person kicks"},
               "timeline": [{"text": "a person walks", "seconds": 1}, {"text": "a person jumps", "seconds": 0.5,
                                                                          "gravity": -1.6}]}
    try:
        report = run_experiment(write(setup, "editing", editing=options), progress=False, text_encoder=hash_text)
    finally:
        (corpus / "manifest.json").unlink()
    rows = {(r["part"], r.get("gravity", r.get("case"))): r for r in report["rows"]}
    assert set(rows) == {("replay", -9.81), ("replay", -1.6), ("keyframes", "in-between"),
                         ("keyframes", "continuation"), ("keyframes", "path"), ("keyframes", "pinned"),
                         ("keep", None), ("timeline", None)}
    assert rows[("replay", -9.81)]["changed_m"]["mean"] < 0.01  # Earth gives the clip back
    assert all(rows[("keyframes", c)]["worst_error_cm"] < 2.0 for c in ("in-between", "continuation", "path", "pinned"))
    keep = rows[("keep", None)]["halves"]
    assert set(keep) == {"lower", "upper"} and all(h["worst_error_cm"] < 2.0 for h in keep.values())
    timeline = rows[("timeline", None)]
    assert timeline["frames"] == 30 and len(timeline["seams"]) == 1
    md = (setup["root"] / "reports/editing/report.md").read_text()
    assert "| SimDiff | -1.6 |" in md and "editing_timeline.png" in md and "| SimDiff | upper | a person kicks |" in md
    assert (setup["root"] / "reports/editing/editing_replay.png").is_file()


def test_following_reports_pass_rates_on_real_clips_and_wordings(setup: dict[str, Path]) -> None:
    corpus = setup["corpus"]
    ids = sorted(p.stem for p in (corpus / "new_joints").glob("*.npy"))
    test = set((corpus / "test.txt").read_text().split())
    clips = [{"id": i, "mirror_of": None, "captions": ["a person jumps in place" if int(i) % 2 else "a person waves"],
              "split": "test" if i in test else "train"} for i in ids]
    (corpus / "manifest.json").write_text(json.dumps({"clips": clips}))
    words = [{"category": "in place", "text": "a person jumps in place", "checks": ["travel:in_place"]},
             {"category": "speed", "text": "a person walks slowly", "checks": ["speed:slower"],
              "reference": "a person walks"}]
    options = {"prompts": {"test": words}, "seeds": 2, "length": 40,
               "ground_truth": [{"category": "in place", "check": "travel:in_place", "captions": "in place"},
                                {"category": "turning", "check": "turn:around", "captions": "turns around"}]}
    try:
        report = run_experiment(write(setup, "following", following=options), progress=False, text_encoder=hash_text)
    finally:
        (corpus / "manifest.json").unlink()
    rows = {r["method"]: r for r in report["rows"]}  # one row per model, every category's wordings in it
    gt = {r["check"]: r for r in rows["ground truth"]["rules"]}
    assert gt["travel:in_place"]["n"] == sum(1 for c in clips if c["split"] == "test" and int(c["id"]) % 2)
    assert gt["turn:around"]["n"] == 0
    model = [r for r in report["rows"] if r["method"] != "ground truth"][0]
    speed = [w for w in model["wordings"] if w["category"] == "speed"]
    assert [len(w["seeds"]) for w in speed] == [2] and [w["category"] for w in model["wordings"]] == ["in place", "speed"]
    assert all(s["readings"][0].startswith("pelvis speed") for s in speed[0]["seeds"])
    md = (setup["root"] / "reports/following/report.md").read_text()
    assert "| turning | — (none) |" in md and "| speed | a person walks slowly | `speed:slower` |" in md
    bad = {**options, "prompts": {"test": [{**words[1], "reference": ""}]}}
    with pytest.raises(SimdiffError, match="needs a 'reference'"):
        run_experiment(write(setup, "following", name="following_bad", following=bad), progress=False,
                       text_encoder=hash_text)


def test_heldout_measures_all_and_unseen_captions(setup: dict[str, Path]) -> None:
    from simdiff.data.humanml3d import normalise_caption, read_captions

    corpus = setup["corpus"]
    texts = corpus / "texts"
    train = (corpus / "train.txt").read_text().split()
    test = (corpus / "test.txt").read_text().split()
    seen = {normalise_caption(c.text) for i in train for c in read_captions(texts / f"{i}.txt")}
    originals = {i: (texts / f"{i}.txt").read_text() for i in test}
    try:  # a third of the test clips get a caption no train clip has; one more repeats a train caption in capitals
        for k, i in enumerate(test):
            if k % 3 == 0:
                (texts / f"{i}.txt").write_text(f"Someone juggles {k} clubs#x/OTHER#0.0#0.0\n")
        first = read_captions(texts / f"{train[0]}.txt")[0].text
        (texts / f"{test[1]}.txt").write_text(f"{first.upper()}!#x/OTHER#0.0#0.0\n")
        unseen = sum(1 for i in test if normalise_caption(read_captions(texts / f"{i}.txt")[0].text) not in seen)
        proto = {**PROTO, "batch_size": 2, "replications": 2, "mm_prompts": 0, "physics": False}
        report = run_experiment(write(setup, "heldout", protocol=proto,
                                      models=[{"name": "MDM", "model": "backbone", **FAST}]),
                                progress=False, text_encoder=hash_text)
    finally:
        for i, text in originals.items():
            (texts / f"{i}.txt").write_text(text)
    rows = {(r["method"], r["captions"]): r for r in report["rows"]}
    assert set(rows) == {("Ground truth", "all"), ("Ground truth", "unseen"), ("MDM", "all"), ("MDM", "unseen")}
    assert normalise_caption(first.upper() + "!") in seen and len(test) // 3 <= unseen < len(test)
    assert rows[("MDM", "unseen")]["items"] == unseen and rows[("MDM", "all")]["items"] == len(test)
    assert rows[("Ground truth", "unseen")]["distinct_captions"] == unseen
    md = (setup["root"] / "reports/heldout/report.md").read_text()
    assert f"| MDM | unseen | {unseen} ({unseen}) |" in md


def test_paired_differences_pair_rows_by_replication() -> None:
    from simdiff.eval.experiments.tables import PAIRED_METRICS, paired_differences

    def row(method: str, r3: list[float], compare_to: str | None = None) -> dict:
        reps = [{**{k: 1.0 for k in PAIRED_METRICS}, "r_precision_top3": v} for v in r3]
        return {"method": method, "sampler": "ddim", "alpha": None, "replications": reps, "compare_to": compare_to}

    rows = [row("fast", [0.5, 0.7, 0.9], compare_to="slow"), row("slow", [0.6, 0.8, 1.0]), row("other", [0.1, 0.1, 0.1])]
    lines = paired_differences(rows)
    assert len(lines) == 3 and lines[2].startswith("* fast − slow (3 paired replications): R@3↑ -0.100 ± 0.000")
    assert "FID↓ +0.000" in lines[2]
    assert paired_differences(rows[1:]) == []  # nothing to compare
