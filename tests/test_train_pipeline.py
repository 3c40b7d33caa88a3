"""``simdiff train pipeline``: all stages on a tiny corpus, skipped when current, re-run downstream of a change."""

from __future__ import annotations

import json

import pytest

from simdiff.errors import SimdiffError
from simdiff.inference.generator import MotionGenerator
from simdiff.train.pipeline import budget_config, run_pipeline
from simdiff.train.pipeline.config import set_option
from simdiff.train.testing import EchoProjector, HashTextEncoder

STAGES = ["corpus", "augment", "backbone", "adapters", "evaluator", "evaluation", "export"]


pytestmark = pytest.mark.usefixtures("one_torch_thread")



@pytest.fixture(scope="module")
def corpus(tiny_corpus):
    """The tiny corpus with a made-up manifest: CMU clips, and one non-commercial clip in the train split."""
    from provenance_fixtures import clip, write_manifest

    splits = {s: (tiny_corpus / f"{s}.txt").read_text().split() for s in ("train", "val", "test")}
    clips = [clip(cid, "CC-BY-NC-4.0" if cid == splits["train"][-1] else "CMU", 2.4, split, "bandai" if
                  cid == splits["train"][-1] else "cmu-amc") | {"motion_type": "walk"}
             for split, ids in splits.items() for cid in ids]
    write_manifest(tiny_corpus, clips)
    return tiny_corpus


def _run(config, out, **kw):
    lines: list[str] = []
    plans = run_pipeline(config, out, text_encoder=HashTextEncoder(), projector=EchoProjector(), progress=False,
                         log=lines.append, **kw)
    return {p.name: p.status for p in plans}, lines


def test_quick_pipeline_runs_skips_and_reruns_downstream(corpus, tmp_path) -> None:
    config = budget_config("quick")
    config.corpus.path = str(corpus)
    out = tmp_path / "run"
    first, _ = _run(config, out)
    assert list(first) == STAGES and set(first.values()) == {"run"}
    for stage in STAGES:
        assert json.loads((out / "stages" / f"{stage}.json").read_text())["key"]
    assert (out / "augmented" / "env.json").is_file()
    assert json.loads((out / "stages" / "backbone.json").read_text())["summary"]["step"] == config.backbone.steps
    evaluation = json.loads((out / "evaluation" / "evaluation.json").read_text())
    assert "r_precision_top3" in evaluation["summary"]["generated"]
    export = out / "export"
    assert {p.name for p in (export / "model").iterdir()} >= {"config.json", "model.safetensors", "sampling.json",
                                                              "README.md"}
    shards = sorted(p.name for p in (export / "sharded").glob("model-*.safetensors"))
    assert len(shards) > 1 and all((export / "sharded" / s).stat().st_size <= 0.25 * 2**20 for s in shards)
    gen = MotionGenerator.load(export / "sharded", load_text=False)
    assert gen.is_simdiff
    assert json.loads((out / "augmented" / "source_corpus.json").read_text())["path"] == str(corpus.resolve())
    provenance = json.loads((export / "model" / "provenance.json").read_text())  # the backbone saw the NC clip
    assert provenance["weights_licence"] == "non-commercial (CC-BY-NC-4.0 motion in the training data)"
    assert [p["what"] for p in provenance["trained_on"]] == ["backbone", "adapters"]
    assert provenance["trained_on"][0]["licences"] == {"CC-BY-NC-4.0": 0.0007, "CMU": 0.0047}  # 1 and 7 clips of 2.4 s
    assert "Weights licence: **non-commercial" in (export / "model" / "README.md").read_text()
    assert (export / "sharded" / "provenance.json").is_file()
    evaluator = json.loads((out / "evaluator" / "provenance.json").read_text())
    assert [p["what"] for p in evaluator["trained_on"]] == ["evaluator"] and "non-commercial" in evaluator["weights_licence"]
    mtime = (out / "backbone" / "model" / "model.safetensors").stat().st_mtime_ns

    again, lines = _run(config, out)
    assert set(again.values()) == {"current"} and sum("skipped" in line for line in lines) == len(STAGES)
    assert (out / "backbone" / "model" / "model.safetensors").stat().st_mtime_ns == mtime

    set_option(config, "adapters.steps=5")
    changed, _ = _run(config, out)
    assert changed == {"corpus": "current", "augment": "current", "backbone": "current", "adapters": "run",
                       "evaluator": "current", "evaluation": "run", "export": "run"}
    assert (out / "backbone" / "model" / "model.safetensors").stat().st_mtime_ns == mtime
    assert json.loads((out / "stages" / "adapters.json").read_text())["summary"]["step"] == 5

    shards = {p.name: p.stat().st_mtime_ns for p in (out / "augmented" / "shards").glob("*.json")}
    set_option(config, "augment.filter.max_pose_d_l2=3.0")  # re-finalised from the shards, the backbone is kept
    refiltered, _ = _run(config, out)
    assert refiltered["augment"] == "run" and refiltered["backbone"] == "current" and refiltered["adapters"] == "run"
    report = json.loads((out / "augmented" / "report.json").read_text())
    assert report["filter"]["thresholds"]["max_pose_d_l2"] == 3.0
    assert {p.name: p.stat().st_mtime_ns for p in (out / "augmented" / "shards").glob("*.json")} == shards

    config.seed += 1
    dry, lines = _run(config, out, dry_run=True)
    assert dry["corpus"] == "current" and all(dry[s] == "run" for s in STAGES[1:])
    assert json.loads((out / "stages" / "adapters.json").read_text())["summary"]["step"] == 5  # nothing ran


def test_interrupted_training_stage_resumes(corpus, tmp_path, monkeypatch) -> None:
    from simdiff.train.pipeline import stages

    config = budget_config("quick")
    config.corpus.path = str(corpus)
    config.backbone.steps, config.backbone.save_every = 6, 3
    real = stages.RUN["adapters"]

    def boom(ctx):
        raise KeyboardInterrupt

    monkeypatch.setitem(stages.RUN, "adapters", boom)
    with pytest.raises(KeyboardInterrupt):
        _run(config, tmp_path)
    assert (tmp_path / "stages" / "adapters.started.json").is_file()
    monkeypatch.setitem(stages.RUN, "adapters", real)
    status, _ = _run(config, tmp_path)
    assert status["backbone"] == "current" and status["adapters"] == "resume"


def test_bad_settings_are_one_line_errors(corpus) -> None:
    config = budget_config("quick")
    with pytest.raises(SimdiffError, match="corpus.path"):
        _run(config, "/nonexistent/never", dry_run=True)
    with pytest.raises(SimdiffError, match="unknown budget"):
        budget_config("tpu")
    with pytest.raises(SimdiffError, match="unknown setting"):
        set_option(config, "backbone.stepz=3")
    with pytest.raises(SimdiffError, match="must be int"):
        set_option(config, "backbone.steps=many")
    assert budget_config("gpu").backbone.size == "mdm" and budget_config("gpu").augment.workers == 16
    set_option(config, "augment.filter.max_pose_d_l2=4")  # a frozen section: replaced, not mutated
    set_option(config, "evaluation.env=[-3.7, 0, 0]")
    assert config.augment.filter.max_pose_d_l2 == 4.0 and config.evaluation.env == (-3.7, 0, 0)
    assert budget_config("quick").augment.filter.max_pose_d_l2 != 4.0


def test_cli_dry_run_prints_the_plan(corpus, tmp_path, capsys) -> None:
    from simdiff.cli.main import main

    argv = ["train", "pipeline", "--budget", "quick", "--corpus", str(corpus), "--out", str(tmp_path / "r"), "--dry-run"]
    assert main(argv + ["--set", "backbone.steps=3", "--seed", "4"]) == 0
    lines = [line.split() for line in capsys.readouterr().out.strip().splitlines()]
    assert [line[0] for line in lines] == STAGES and all(line[1] == "run" for line in lines)
    assert not (tmp_path / "r").exists()
    assert main(argv + ["--set", "backbone.nope=1"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "unknown setting" in err


def test_wall_clock_cap_stops_training_at_a_checkpoint(tmp_path) -> None:
    from simdiff.train import Trainer, synthetic_dataset
    from simdiff.train.pipeline.context import PipelineContext
    from simdiff.train.pipeline.stages import _train
    from simdiff.train.state import latest_checkpoint
    from simdiff.train.testing import tiny_run_config

    trainer = Trainer(tmp_path, tiny_run_config(9, save_every=3), synthetic_dataset(4, 30, max_frames=30),
                      text_encoder=HashTextEncoder())
    ctx = PipelineContext(out=tmp_path, config=budget_config("quick"), progress=False)
    summary = _train(ctx, trainer, max_minutes=1e-9)
    assert summary["step"] == 3 and summary["steps"] == 9
    assert latest_checkpoint(tmp_path).name == "step_000000003"


class RejectingProjector(EchoProjector):
    """Every rollout fails the faithfulness test."""

    def __call__(self, motions, envs):
        for rollout, info in super().__call__(motions, envs):
            yield rollout, {**info, "d_l2_pose": 99.0}


def test_empty_augmented_corpus_is_a_clear_error(corpus, tmp_path) -> None:
    config = budget_config("quick")
    config.corpus.path = str(corpus)
    with pytest.raises(SimdiffError, match="kept no training clip.*report.md"):
        run_pipeline(config, tmp_path, text_encoder=HashTextEncoder(), projector=RejectingProjector(), progress=False,
                     log=lambda line: None)
    assert json.loads((tmp_path / "stages" / "backbone.json").read_text())["key"]  # upstream work is kept
    assert not (tmp_path / "stages" / "adapters.json").exists()
