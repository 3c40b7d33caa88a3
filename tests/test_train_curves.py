"""Learning-curve tooling: points are measured in training CPU time, written as JSON and a PNG."""

from __future__ import annotations

import json

import pytest

from simdiff.errors import SimdiffError
from simdiff.eval.testing import write_tiny_corpus
from simdiff.train.curves import DESIGNS, design_config
from benchmark_fixtures import load_benchmark


pytestmark = pytest.mark.usefixtures("one_torch_thread")


def test_train_curves_script_writes_json_and_png(tmp_path) -> None:
    corpus = write_tiny_corpus(tmp_path / "c", n_train=8, n_val=4, n_test=4, frames=48)
    module = load_benchmark("train_curves")
    out = tmp_path / "reports"
    argv = ["--corpus", str(corpus), "--design", "tiny_plain", "--minutes", "0.02", "--points", "2",
            "--text-encoder", "hash", "--out", str(out), "--heldout", "4", "--sample-steps", "2"]
    assert module.main(argv) == 0
    curves = json.loads((out / "curves.json").read_text())
    pts = curves["tiny_plain"]["points"]
    assert len(pts) == 2 and pts[1]["step"] > pts[0]["step"] >= 1 and pts[1]["cpu_s"] >= 1.2
    for row in pts:
        assert row["heldout_loss"] > 0 and row["sliding"] >= 0 and 0 <= row["skate_ratio"] <= 1
        assert row["r_precision_top3"] is None  # no evaluator given: not measured
    assert curves["tiny_plain"]["heldout_split"] == "val"
    assert (out / "curves.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_designs_are_mdm_transformers_with_optional_geometric_losses() -> None:
    assert design_config("mdm_geo_crop", "minilm", 384, 0).model.backbone.num_layers == 8
    geo = design_config("small_geo_crop", "minilm", 384, 0).train
    assert geo.losses.velocity > 0 and geo.crop.max_frames == 120
    assert not design_config("small_plain", "minilm", 384, 0).train.losses.active
    assert set(DESIGNS) >= {"small_plain", "small_geo_crop", "mdm_geo_crop"}
    with pytest.raises(SimdiffError, match="unknown design"):
        design_config("latent", "minilm", 384, 0)


def test_curve_run_continues_from_its_folder_and_rescores_saved_samples(tmp_path) -> None:
    corpus = write_tiny_corpus(tmp_path / "c", n_train=8, n_val=4, n_test=4, frames=48)
    module = load_benchmark("train_curves")
    out, run = tmp_path / "reports", tmp_path / "run"
    base = ["--corpus", str(corpus), "--design", "tiny_plain", "--points", "1", "--text-encoder", "hash",
            "--out", str(out), "--heldout", "4", "--sample-steps", "2", "--run-dir", str(run)]
    assert module.main(base + ["--minutes", "0.01"]) == 0
    first = json.loads((out / "curves.json").read_text())["tiny_plain"]["points"]
    assert len(first) == 1 and (run / "checkpoints").is_dir()
    assert module.main(base + ["--minutes", "0.02"]) == 0  # continues: one more point, later step, more CPU
    pts = json.loads((out / "curves.json").read_text())["tiny_plain"]["points"]
    assert len(pts) == 2 and pts[0] == first[0]
    assert pts[1]["step"] > pts[0]["step"] and pts[1]["cpu_s"] >= 1.2 and pts[0]["cpu_s"] < pts[1]["cpu_s"]
    assert len(list((run / "curve_samples").glob("step_*.npy"))) == 2
    # rescoring the saved samples without training reproduces the sample metrics
    assert module.main(base + ["--minutes", "0.02", "--rescore"]) == 0
    again = json.loads((out / "curves.json").read_text())["tiny_plain"]["points"]
    assert [r["step"] for r in again] == [r["step"] for r in pts]
    for a, b in zip(again, pts):
        assert abs(a["sliding"] - b["sliding"]) < 1e-6 and abs(a["skate_ratio"] - b["skate_ratio"]) < 1e-6
