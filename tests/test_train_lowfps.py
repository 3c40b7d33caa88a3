"""The cheaper, lower-frame-rate design: resampling, the 10 fps corpus, its learning curve."""

from __future__ import annotations

import json

import numpy as np
import pytest

from simdiff.data.humanml3d import HumanML3D
from simdiff.errors import SimdiffError
from simdiff.eval.testing import write_tiny_corpus
from simdiff.motion.features import process_joints
from simdiff.motion.synthetic import walk
from simdiff.train.lowfps import build_lowfps_corpus, downsample_features, upsample_features, upsample_joints
from benchmark_fixtures import load_benchmark


pytestmark = pytest.mark.usefixtures("one_torch_thread")


def test_resampling_shapes_and_exact_keyframes() -> None:
    feats = process_joints(walk(81, speed=1.2)).features
    low = downsample_features(feats, 2)
    assert feats.shape == (80, 263) and low.shape == (40, 263)
    assert upsample_features(low, 2).shape == (80, 263)
    j = np.random.default_rng(0).normal(size=(5, 22, 3)).astype(np.float32)
    up = upsample_joints(j, 3)
    assert up.shape == (13, 22, 3) and np.allclose(up[::3], j) and np.allclose(up[1], (2 * j[0] + j[1]) / 3, atol=1e-6)


@pytest.mark.parametrize("speed, contact", [(0.6, 1.0), (1.2, 0.0)])
def test_contact_threshold_is_the_same_speed_at_both_rates(speed: float, contact: float) -> None:
    pose = walk(2, speed=0.0)[0]
    glide = np.stack([pose + np.array([0.0, 0.0, speed * t / 20.0], dtype=np.float32) for t in range(61)])
    fast = process_joints(glide).features
    slow = downsample_features(fast, 2)
    assert fast[5:-5, 259:263].mean() == contact and slow[3:-3, 259:263].mean() == contact


def test_lowfps_corpus_is_built_resumably(tmp_path) -> None:
    src = write_tiny_corpus(tmp_path / "src", n_train=6, n_val=2, n_test=2, frames=48)
    n = build_lowfps_corpus(src, tmp_path / "low", 2, progress=False)
    assert n == 10
    clip = (src / "train.txt").read_text().split()[0]
    assert np.load(tmp_path / "low" / "new_joint_vecs" / f"{clip}.npy").shape == (23, 263)
    assert (tmp_path / "low" / "train.txt").read_text() == (src / "train.txt").read_text()
    assert len(HumanML3D(tmp_path / "low", "train", min_frames=20)) == 6
    assert len(HumanML3D(tmp_path / "low", "train")) == 0  # MDM's 40-frame minimum would drop every clip
    stamp = (tmp_path / "low" / "new_joint_vecs" / f"{clip}.npy").stat().st_mtime_ns
    assert build_lowfps_corpus(src, tmp_path / "low", 2, progress=False) == 10
    assert (tmp_path / "low" / "new_joint_vecs" / f"{clip}.npy").stat().st_mtime_ns == stamp
    with pytest.raises(SimdiffError, match="other settings"):
        build_lowfps_corpus(src, tmp_path / "low", 3, progress=False)


def test_lowfps_learning_curve_is_measured_at_20_fps(tmp_path) -> None:
    corpus = write_tiny_corpus(tmp_path / "c", n_train=8, n_val=4, n_test=4, frames=48)
    module = load_benchmark("train_curves")
    out = tmp_path / "reports"
    argv = ["--corpus", str(corpus), "--design", "tiny_lowfps2", "--minutes", "0.01", "--points", "1",
            "--text-encoder", "hash", "--out", str(out), "--heldout", "4", "--sample-steps", "2"]
    assert module.main(argv) == 2  # needs --lowfps-corpus
    assert module.main(argv + ["--lowfps-corpus", str(tmp_path / "low")]) == 0
    curve = json.loads((out / "curves.json").read_text())["tiny_lowfps2"]
    assert curve["fps"] == 10 and curve["points"][0]["step"] >= 1
    assert curve["ground_truth"]["sliding"] >= 0 and curve["points"][0]["heldout_loss"] > 0
