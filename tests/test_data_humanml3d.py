"""Tests for simdiff.data.humanml3d on a tiny HumanML3D-style directory."""

from __future__ import annotations

from collections import Counter
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
import torch
from torch.utils.data import DataLoader

from simdiff.data.humanml3d import HumanML3D, build_items, collate, normalise_caption, read_captions, read_split
from simdiff.errors import MotionFormatError, SimdiffError

FRAMES = {"000001": 80, "000002": 30, "000003": 150, "000004": 220, "000005": 100}
TEXTS = {
    "000001": [
        "a person walks forward.#a/DET person/NOUN walk/VERB forward/ADV#0.0#0.0",
        "someone strolls ahead#someone/PRON stroll/VERB ahead/ADV#0.0#0.0",
    ],
    "000002": ["too short#too/ADV short/ADJ#0.0#0.0"],
    "000003": [
        "a person jumps#a/DET person/NOUN jump/VERB#0.0#0.0",
        "a person bends down#a/DET person/NOUN bend/VERB down/ADV#1.18#4.0",  # int(23.6) = 23 .. 80
        "a person waves#a/DET person/NOUN wave/VERB#0.0#1.5",  # 30 frames: dropped
        "a person sits#a/DET person/NOUN sit/VERB#5.0#9.0",  # 100..180 -> 100..150
    ],
    "000004": ["too long#too/ADV long/ADJ#0.0#0.0", "a cut#a/DET cut/NOUN#0.0#3.0"],
    "000005": ["a person kicks#a/DET person/NOUN kick/VERB#0.5#3.0", ""],  # 10..60 only
}


@pytest.fixture()
def hml_dir(tmp_path: Path) -> Path:
    rng = np.random.default_rng(0)
    (tmp_path / "new_joint_vecs").mkdir()
    (tmp_path / "texts").mkdir()
    for clip_id, frames in FRAMES.items():
        np.save(tmp_path / "new_joint_vecs" / f"{clip_id}.npy", rng.normal(size=(frames, 263)).astype(np.float32))
        (tmp_path / "texts" / f"{clip_id}.txt").write_text("\n".join(TEXTS[clip_id]) + "\n")
    np.save(tmp_path / "Mean.npy", rng.normal(size=263).astype(np.float32))
    np.save(tmp_path / "Std.npy", rng.uniform(0.5, 2.0, size=263).astype(np.float32))
    (tmp_path / "train.txt").write_text("\n".join([*FRAMES, "000006"]) + "\n")  # 000006 has no files
    (tmp_path / "test.txt").write_text("000003\n")
    return tmp_path


def raw(root: Path, clip_id: str) -> np.ndarray:
    return np.load(root / "new_joint_vecs" / f"{clip_id}.npy")


def normalise(root: Path, x: np.ndarray) -> np.ndarray:
    return (x - np.load(root / "Mean.npy")) / np.load(root / "Std.npy")


def test_items_follow_mdm_rules(hml_dir: Path) -> None:
    items = build_items(hml_dir, read_split(hml_dir / "train.txt"))
    spans = sorted((i.name, i.clip_id, i.start, i.stop, len(i.captions)) for i in items)
    assert spans == [
        ("000001", "000001", 0, 80, 2),
        ("000003", "000003", 0, 150, 1),
        ("000003_100_150", "000003", 100, 150, 1),
        ("000003_23_80", "000003", 23, 80, 1),  # int(1.18 * 20) == 23 (truncated, as MDM cuts)
        ("000005_10_60", "000005", 10, 60, 1),
    ]
    caption = next(i for i in items if i.name == "000003_23_80").captions[0]
    assert caption.text == "a person bends down"
    assert caption.tokens == ("a/DET", "person/NOUN", "bend/VERB", "down/ADV")


def test_uncropped_items_are_normalised_and_zero_padded(hml_dir: Path) -> None:
    ds = HumanML3D(hml_dir, "train", unit_length=0)
    assert len(ds) == 5
    by_name = {item.name: i for i, item in enumerate(ds.items)}
    out = ds[by_name["000003_23_80"]]
    assert out["motion"].shape == (196, 263) and out["motion"].dtype == np.float32
    assert out["length"] == 57 and out["id"] == "000003_23_80"
    np.testing.assert_allclose(out["motion"][:57], normalise(hml_dir, raw(hml_dir, "000003")[23:80]), atol=1e-5)
    assert not out["motion"][57:].any()
    assert out["caption"] == "a person bends down"
    assert out["tokens"] == ["a/DET", "person/NOUN", "bend/VERB", "down/ADV"]


def test_unit_length_crop(hml_dir: Path) -> None:
    ds = HumanML3D(hml_dir, "train", seed=7)
    index = next(i for i, item in enumerate(ds.items) if item.name == "000003_23_80")
    source = normalise(hml_dir, raw(hml_dir, "000003")[23:80])
    lengths = Counter()
    for _ in range(300):
        out = ds[index]
        n = out["length"]
        lengths[n] += 1
        # A contiguous window of the 57-frame cut, then zeros.
        offsets = [o for o in range(57 - n + 1) if np.allclose(out["motion"][:n], source[o : o + n], atol=1e-5)]
        assert offsets
        assert not out["motion"][n:].any()
    assert set(lengths) == {56, 52}  # 57 // 4 * 4 and (57 // 4 - 1) * 4
    assert 0.55 < lengths[56] / 300 < 0.78  # 2/3 single, 1/3 double


def test_random_caption_is_seeded(hml_dir: Path) -> None:
    index = next(i for i, item in enumerate(HumanML3D(hml_dir).items) if item.name == "000001")
    ds1, ds2 = HumanML3D(hml_dir, seed=3), HumanML3D(hml_dir, seed=3)
    seq1 = [ds1[index]["caption"] for _ in range(40)]
    assert seq1 == [ds2[index]["caption"] for _ in range(40)]
    assert set(seq1) == {"a person walks forward.", "someone strolls ahead"}
    out = ds1.get(index, np.random.default_rng(0))  # explicit generator
    assert out["length"] in (80, 76)


def test_each_worker_gets_its_own_stream(hml_dir: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    import simdiff.data.humanml3d as module

    def lengths_in_worker(worker_seed: int) -> list[int]:
        monkeypatch.setattr(module, "get_worker_info", lambda: SimpleNamespace(seed=worker_seed))
        ds = HumanML3D(hml_dir, seed=0)
        return [ds[2]["length"] for _ in range(30)]

    assert lengths_in_worker(100) == lengths_in_worker(100)
    assert lengths_in_worker(100) != lengths_in_worker(101)


def test_collate_and_dataloader(hml_dir: Path) -> None:
    ds = HumanML3D(hml_dir, "train")
    batch = collate([ds[i] for i in range(len(ds))])
    assert batch["motion"].shape == (5, 196, 263) and batch["motion"].dtype == torch.float32
    assert batch["lengths"].dtype == torch.int64
    assert batch["mask"].shape == (5, 196) and batch["mask"].dtype == torch.bool
    assert torch.equal(batch["mask"].sum(dim=1), batch["lengths"])
    assert batch["ids"] == [item.name for item in ds.items]
    assert len(batch["captions"]) == len(batch["tokens"]) == 5
    assert not batch["motion"][~batch["mask"]].any()
    loader = DataLoader(ds, batch_size=2, shuffle=True, num_workers=2, collate_fn=collate)
    seen = []
    for b in loader:
        assert b["motion"].shape[1:] == (196, 263)
        assert all(n % 4 == 0 for n in b["lengths"].tolist())
        seen += b["ids"]
    assert sorted(seen) == sorted(item.name for item in ds.items)


def test_test_split_and_errors(hml_dir: Path, tmp_path_factory: pytest.TempPathFactory) -> None:
    assert [i.name for i in HumanML3D(hml_dir, "test").items] == ["000003_23_80", "000003_100_150", "000003"]
    with pytest.raises(SimdiffError, match="'dev'"):
        HumanML3D(hml_dir, "dev")
    with pytest.raises(SimdiffError, match="val.txt"):
        HumanML3D(hml_dir, "val")
    empty = tmp_path_factory.mktemp("empty")
    with pytest.raises(SimdiffError, match="Mean.npy"):
        HumanML3D(empty, [])
    bad = hml_dir / "texts" / "bad.txt"
    bad.write_text("fine#a/DET#0.0#0.0\nno separators here\n")
    with pytest.raises(MotionFormatError, match="bad.txt:2"):
        read_captions(bad)
    bad.write_text("nan tags#a/DET#nan#nan\n")
    assert read_captions(bad)[0].whole


def test_a_split_is_any_id_list_in_the_folder_and_an_unknown_one_is_named(tmp_path: Path) -> None:
    from simdiff.data.humanml3d import HumanML3D, read_split
    from simdiff.errors import SimdiffError
    from simdiff.eval.testing import write_tiny_corpus

    root = write_tiny_corpus(tmp_path / "c", n_train=4, n_test=2)
    train = read_split(root / "train.txt")
    (root / "first_try.txt").write_text("\n".join(train[:2]) + "\n", encoding="utf-8")
    ds = HumanML3D(root, "first_try", unit_length=0)
    assert sorted({item.clip_id for item in ds.items}) == sorted(train[:2])
    with pytest.raises(SimdiffError, match=r"unknown split 'second_try'; expected one of .*first_try"):
        HumanML3D(root, "second_try")
    with pytest.raises(SimdiffError, match="unknown split '../c/train'"):
        HumanML3D(root, "../c/train")


def test_unseen_in_keeps_only_captions_the_other_split_lacks(hml_dir: Path) -> None:
    assert normalise_caption("  A person, walks-FORWARD. ") == "a person walks forward"
    (hml_dir / "val.txt").write_text("000003\n000001\n")
    (hml_dir / "train.txt").write_text("000005\n")
    (hml_dir / "texts" / "000005.txt").write_text("A PERSON JUMPS!#x/OTHER#0.0#0.0\nsomeone strolls ahead#x/OTHER#0.0#0.0\n")
    items = {it.name: [c.text for c in it.captions] for it in HumanML3D(hml_dir, "val", unseen_in="train").items}
    # 000003's whole-clip "a person jumps" is a train caption once normalised; its segments keep theirs
    assert items == {"000003_23_80": ["a person bends down"], "000003_100_150": ["a person sits"],
                     "000001": ["a person walks forward."]}
    assert len(HumanML3D(hml_dir, "val").items) == 4
    with pytest.raises(SimdiffError, match="no item of split 'val' has a caption that 'val' lacks"):
        HumanML3D(hml_dir, "val", unseen_in="val")
