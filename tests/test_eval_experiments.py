"""Protocol and experiment runner end to end on tiny random models and a tiny synthetic corpus."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import torch

from simdiff.eval.evaluator import EvaluatorConfig, OurEvaluator, TextMotionEvaluator, save_evaluator
from simdiff.eval.experiments import load_config, run_experiment
from simdiff.eval.protocol import ProtocolConfig, evaluate_t2m
from simdiff.eval.testing import write_tiny_corpus
from simdiff.model import ModelConfig, MotionGenerator, SimConfig, backbone_preset, build_network
from simdiff.train.testing import HashTextEncoder
from simdiff.data.humanml3d import HumanML3D

PROTO = {"replications": 2, "batch_size": 8, "samples_limit": 8, "diversity_times": 8, "seed": 0}


@pytest.fixture(scope="module")
def setup(tmp_path_factory: pytest.TempPathFactory) -> dict:
    root = tmp_path_factory.mktemp("exp")
    corpus = write_tiny_corpus(root / "corpus", n_train=4, n_test=16, frames=44)
    mean = torch.from_numpy(np.load(corpus / "Mean.npy"))
    std = torch.from_numpy(np.load(corpus / "Std.npy"))
    torch.manual_seed(0)
    for name, sim in (("backbone", None), ("simdiff", SimConfig())):
        cfg = ModelConfig(backbone=backbone_preset("tiny"), sim=sim)
        MotionGenerator(build_network(cfg), cfg, None, mean, std).save(root / name)
    ev = TextMotionEvaluator(EvaluatorConfig(movement_dim=16, motion_hidden=16, text_hidden=16, embed_dim=8), mean, std)
    save_evaluator(root / "evaluator", ev)
    return {"root": root, "corpus": corpus}


def write_config(setup: dict, kind: str, **extra) -> Path:
    root = setup["root"]
    models = extra.pop("models", [{"name": "mdm", "path": str(root / "backbone"), "steps": 5}])
    cfg = {"name": f"test_{kind}", "kind": kind, "corpus": str(setup["corpus"]), "models": models,
           "evaluator": {"kind": "ours", "path": str(root / "evaluator")}, "protocol": PROTO,
           "out_dir": str(root / "reports"), "text_encoder": "hash", **extra}
    path = root / f"eval_{kind}.json"
    path.write_text(json.dumps(cfg))
    return path


class FakeSim:
    def __call__(self, motions, envs):
        for i, m in enumerate(motions):
            yield m, {"success": i % 2 == 0, "d_l2": 5.0, "err_mm": 40.0}


def test_protocol_gt_only_is_sane(setup: dict) -> None:
    ds = HumanML3D(setup["corpus"], "test")
    torch.manual_seed(1)
    model = TextMotionEvaluator(EvaluatorConfig(movement_dim=16, motion_hidden=16, text_hidden=16, embed_dim=8),
                                torch.from_numpy(ds.normalizer.mean), torch.from_numpy(ds.normalizer.std))
    result = evaluate_t2m(OurEvaluator(model, HashTextEncoder()), ds, None, ProtocolConfig(**PROTO))
    gt = result["summary"]["ground_truth"]
    assert gt["fid"]["n"] == 2 and gt["fid"]["mean"] >= 0
    assert 0 <= gt["r_precision_top1"]["mean"] <= gt["r_precision_top3"]["mean"] <= 1
    assert result["samples_per_replication"] == 16  # MDM: samples_limit // 32 + 1 batches
    assert "penetration" in gt


def test_table1_with_physdiff_row_and_provenance(setup: dict) -> None:
    root = setup["root"]
    models = [{"name": "mdm", "path": str(root / "backbone"), "steps": 5},
              {"name": "physdiff", "path": str(root / "backbone"), "steps": 5,
               "physdiff": {"steps": 5, "project_at": [200, 0], "guidance": 2.5}}]
    report = run_experiment(write_config(setup, "table1", models=models), projector=FakeSim(), command=["simdiff", "test"],
                            progress=False)
    assert [r["model"] for r in report["rows"]] == ["ground truth", "mdm", "physdiff"]
    for row in report["rows"][1:]:
        s = row["summary"]
        assert {"fid", "r_precision_top1", "mm_dist", "diversity", "penetration"} <= set(s)
        assert s["fid"]["n"] == 2 and row["s_per_sample"] > 0
    prov = report["provenance"]
    assert prov["command"] == "simdiff test" and prov["seed"] == 0 and prov["machine"]["cpus"]
    assert "git_commit" in prov
    out = root / "reports" / "test_table1"
    md = (out / "report.md").read_text()
    assert "physdiff" in md and "git commit" in md
    # rows are cached: a rerun measures nothing new and gives the same numbers
    again = run_experiment(write_config(setup, "table1", models=models), projector=FakeSim(), progress=False)
    assert again["rows"] == report["rows"]


def test_table2_fig4_fig5_retrack(setup: dict) -> None:
    root = setup["root"]
    sim_model = [{"name": "simdiff", "path": str(root / "simdiff"), "steps": 5}]
    envs = [[-9.81, 0, 0], [-3.0, 0, 0]]
    one = {**PROTO, "replications": 1}
    t2 = run_experiment(write_config(setup, "table2", models=sim_model, envs=envs[1:], retrack_samples=4, protocol=one),
                        projector=FakeSim(), progress=False)
    assert len(t2["rows"]) == 2 and t2["rows"][1]["success_rate"] == 0.5 and t2["rows"][0]["env"] == [-3.0, 0, 0]
    f4 = run_experiment(write_config(setup, "fig4", models=sim_model, envs=envs), progress=False)
    assert {"peak_root_height_m", "airborne_fraction", "drift_m"} <= set(f4["rows"][0]["motion"])
    assert (root / "reports" / "test_fig4" / "test_fig4.png").is_file()
    f5 = run_experiment(write_config(setup, "fig5", models=sim_model, alphas=[0.0, 1.0], protocol=one), progress=False)
    assert [r["alpha"] for r in f5["rows"]] == [0.0, 1.0]
    rt = run_experiment(write_config(setup, "retrack", models=sim_model, envs=envs[:1], retrack_samples=3),
                        projector=FakeSim(), progress=False)
    assert rt["rows"][0]["samples"] == 3


def test_shipped_configs_parse() -> None:
    configs = sorted(Path(__file__).resolve().parents[1].glob("configs/eval_*.json"))
    assert configs
    for path in configs:
        load_config(path)
