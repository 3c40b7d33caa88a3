"""The T2M protocol on a tiny synthetic corpus (the experiments themselves: tests/test_experiments.py)."""

from __future__ import annotations

import pytest
import torch

from simdiff.eval.evaluator import EvaluatorConfig, OurEvaluator, TextMotionEvaluator
from simdiff.eval.protocol import ProtocolConfig, evaluate_t2m
from simdiff.eval.testing import write_tiny_corpus
from simdiff.train.testing import HashTextEncoder
from simdiff.data.humanml3d import HumanML3D

PROTO = {"replications": 2, "batch_size": 8, "samples_limit": 8, "diversity_times": 8, "seed": 0}


@pytest.fixture(scope="module")
def setup(tmp_path_factory: pytest.TempPathFactory) -> dict:
    root = tmp_path_factory.mktemp("exp")
    return {"root": root, "corpus": write_tiny_corpus(root / "corpus", n_train=4, n_test=16, frames=44)}


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
