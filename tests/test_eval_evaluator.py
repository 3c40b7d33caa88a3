"""Our text–motion evaluator: shapes, save/load, training on a tiny corpus, resume."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import torch

from simdiff.errors import SimdiffError
from simdiff.eval.evaluator import EvaluatorConfig, OurEvaluator, TextMotionEvaluator, load_evaluator, save_evaluator
from simdiff.eval.testing import write_tiny_corpus
from simdiff.eval.train_evaluator import EvaluatorTrainConfig, contrastive_loss, train_evaluator
from simdiff.train.testing import HashTextEncoder

SMALL = EvaluatorConfig(movement_dim=32, motion_hidden=32, text_hidden=32, embed_dim=16)


def test_shapes_and_padding_invariance() -> None:
    torch.manual_seed(0)
    model = TextMotionEvaluator(SMALL).eval()
    feats = torch.randn(3, 48, 263)
    out = model.embed_motion(feats, [48, 40, 20])
    assert out.shape == (3, 16)
    noisy = feats.clone()
    noisy[2, 20:] = 99.0  # frames beyond the length do not matter
    assert torch.allclose(model.embed_motion(noisy, [48, 40, 20]), out, atol=1e-5)
    assert model.embed_text_vectors(torch.randn(2, 384)).shape == (2, 16)
    assert model.movement(torch.randn(1, 48, 259)).shape == (1, 12, 32)  # one token per 4 frames


def test_save_load_round_trip(tmp_path: Path) -> None:
    model = TextMotionEvaluator(SMALL, torch.full((263,), 1.0), torch.full((263,), 2.0))
    save_evaluator(tmp_path, model, {"note": 1})
    assert sorted(p.name for p in tmp_path.iterdir()) == ["config.json", "model.safetensors"]
    back = load_evaluator(tmp_path)
    assert back.config == SMALL
    for k, v in model.state_dict().items():
        assert torch.equal(back.state_dict()[k], v)
    with pytest.raises(SimdiffError, match="missing"):
        load_evaluator(tmp_path / "nope")


def test_contrastive_loss_prefers_aligned_pairs() -> None:
    t = torch.eye(4) * 20
    good = contrastive_loss(t, t.clone(), ["a", "b", "c", "d"], 10.0, 1)
    bad = contrastive_loss(t, torch.roll(t, 1, 0), ["a", "b", "c", "d"], 10.0, 1)
    assert float(good) == 0.0 and float(bad) > 0
    # identical captions are not negatives
    assert float(contrastive_loss(t, t, ["a"] * 4, 10.0, 1)) == 0.0


def test_training_learns_and_resumes(tmp_path: Path) -> None:
    corpus = write_tiny_corpus(tmp_path / "c", n_train=24, n_val=8, n_test=4, frames=48)
    cfg = EvaluatorTrainConfig(evaluator=SMALL, epochs=2, batch_size=8, seed=1)
    out = tmp_path / "ev"
    first = train_evaluator(corpus, out, cfg, text_encoder=HashTextEncoder(), progress=False)
    assert len(first["history"]) == 2 and "val" in first["history"][0]
    from simdiff.model.provenance import read_provenance

    provenance = read_provenance(out)  # the tiny corpus has no manifest.json: licence unknown, said so
    assert provenance is not None and provenance.trained_on[0].what == "evaluator"
    assert provenance.weights_licence == "unknown (no licence record for c)"
    # resume to 4 epochs == a straight 4-epoch run (deterministic)
    cfg4 = EvaluatorTrainConfig(evaluator=SMALL, epochs=4, batch_size=8, seed=1)
    with pytest.raises(SimdiffError, match="different config"):
        train_evaluator(corpus, out, cfg4, text_encoder=HashTextEncoder(), progress=False)
    import json

    state = json.loads((out / "checkpoint" / "state.json").read_text())
    state["config"]["epochs"] = 4  # extend the run the way the CLI's --epochs does
    (out / "checkpoint" / "state.json").write_text(json.dumps(state))
    resumed = train_evaluator(corpus, out, cfg4, text_encoder=HashTextEncoder(), progress=False)
    straight = train_evaluator(corpus, tmp_path / "ev2", cfg4, text_encoder=HashTextEncoder(), progress=False)
    assert [h["loss"] for h in resumed["history"]] == pytest.approx([h["loss"] for h in straight["history"]], rel=1e-5)
    ev = OurEvaluator.load(out, text_encoder=HashTextEncoder())
    emb = ev.embed_text(["a person walks fast straight ahead"])
    assert emb.shape == (1, 16) and emb.dtype == np.float64
    with pytest.raises(SimdiffError, match="test split"):
        train_evaluator(corpus, tmp_path / "x", EvaluatorTrainConfig(split="test"), text_encoder=HashTextEncoder(), progress=False)
