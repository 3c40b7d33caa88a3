"""Model provenance: the licence rule, manifests, augmented folders, provenance.json I/O, the shipped model."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from provenance_fixtures import clip, write_augmented, write_manifest
from simdiff.errors import SimdiffError
from simdiff.model.provenance import (
    PROVENANCE_NAME,
    SOURCE_CORPUS_NAME,
    Provenance,
    TrainingData,
    provenance_from_corpus,
    read_provenance,
    training_provenance,
    weights_licence,
    write_provenance,
)


def part(*codes: str, data: str = "corpus", what: str = "backbone") -> TrainingData:
    return TrainingData(what=what, data=data, licences={c: 0.5 for c in codes})


@pytest.mark.parametrize("parts, expected", [
    ([part("CMU")], "permissive (CMU)"),
    ([part("MIT"), part("CMU")], "permissive (CMU, MIT)"),
    ([part("CMU", "CC-BY-SA-3.0")], "share-alike (CC-BY-SA-3.0 motion in the training data)"),
    ([part("CMU", "CC-BY-SA-3.0"), part("CC-BY-NC-4.0", what="adapters")],
     "non-commercial (CC-BY-NC-4.0 motion in the training data)"),
    ([part("CMU"), part(data="aug")], "unknown (no licence record for aug)"),
    ([part("CC-BY-NC-4.0"), part(data="aug")], "unknown (no licence record for aug)"),
    ([part(data="synthetic")], "permissive (synthetic data only)"),
    ([part("CMU"), part(data="synthetic")], "permissive (CMU)"),
    ([part("GPL")], "unknown (unrecognised licence code GPL)"),
    ([], "unknown (no training data recorded)"),
])
def test_most_restrictive_licence_wins(parts: list[TrainingData], expected: str) -> None:
    assert weights_licence(parts) == expected
    assert Provenance(parts).weights_licence == expected


def test_corpus_counts_the_split_and_originals_once(tmp_path: Path) -> None:
    corpus = write_manifest(tmp_path / "corpus", [
        clip("a_0", "CMU", 36.0), clip("Ma_0", "CMU", 36.0, mirror_of="a_0"),
        clip("b_0", "MIT", 72.0, source="deepmimic"), clip("Mc_0", "CC-BY-SA-3.0", 18.0, mirror_of="c_0", source="hdm05"),
        clip("c_0", "CC-BY-SA-3.0", 18.0, split="test", source="hdm05"),
        clip("d_0", "CC-BY-NC-4.0", 360.0, split="val", source="bandai"),
    ])
    train = provenance_from_corpus(corpus).trained_on[0]
    # a_0 once (its mirror adds nothing); the train mirror Mc_0 brings its test original c_0
    assert train.licences == {"CC-BY-SA-3.0": 0.005, "CMU": 0.01, "MIT": 0.02}
    assert train.hours == pytest.approx(0.035) and train.sources == ["cmu-amc", "deepmimic", "hdm05"]
    assert (train.what, train.data, train.licence_set) == ("backbone", "corpus", "all")
    assert provenance_from_corpus(corpus).weights_licence.startswith("share-alike")
    val = provenance_from_corpus(corpus, "evaluator", split="val")
    assert val.trained_on[0].licences == {"CC-BY-NC-4.0": 0.1} and val.weights_licence.startswith("non-commercial")
    (corpus / "train.txt").write_text("a_0\nMa_0\n")  # the split file (what the trainer reads) wins
    assert provenance_from_corpus(corpus).trained_on[0].licences == {"CMU": 0.01}


def test_cmu_only_corpus_is_cmu(tmp_path: Path) -> None:
    clips = [{"id": "01_01_00", "seconds": 360.0, "split": "train", "rig": "bvh", "mirror_of": None}]
    corpus = write_manifest(tmp_path / "cmu", clips, fmt="simdiff-cmu-corpus")
    prov = provenance_from_corpus(corpus)
    assert prov.trained_on[0].licences == {"CMU": 0.1} and prov.trained_on[0].sources == ["cmu-bvh"]
    assert prov.weights_licence == "permissive (CMU)"


def test_augmented_folder_follows_its_source_corpus(tmp_path: Path) -> None:
    corpus = write_manifest(tmp_path / "corpus", [clip("a_0", "CMU", 36.0), clip("n_0", "CC-BY-NC-4.0", 36.0)])
    only_cmu = write_augmented(tmp_path / "aug_cmu", ["a_0"], corpus)
    with_nc = write_augmented(tmp_path / "aug_nc", ["a_0", "n_0"], corpus)
    assert json.loads((only_cmu / SOURCE_CORPUS_NAME).read_text())["path"] == str(corpus.resolve())
    cmu = provenance_from_corpus(only_cmu, "adapters")
    assert cmu.weights_licence == "permissive (CMU)" and cmu.trained_on[0].data == "aug_cmu"
    assert "augmented from corpus corpus" in cmu.trained_on[0].note
    assert provenance_from_corpus(with_nc, "adapters").weights_licence.startswith("non-commercial")
    shutil.rmtree(corpus)  # the source corpus is gone: the summary recorded at augmentation time stands in
    recorded = provenance_from_corpus(with_nc, "adapters").trained_on[0]
    assert recorded.licences == {"CC-BY-NC-4.0": 0.01, "CMU": 0.01} and "as recorded" in recorded.note


def test_augmented_folder_without_record(tmp_path: Path) -> None:
    corpus = write_manifest(tmp_path / "corpus", [clip("a_0", "MIT", 36.0)])
    aug = write_augmented(tmp_path / "old_aug", ["a_0"])
    prov = provenance_from_corpus(aug, "adapters")
    assert prov.weights_licence == "unknown (no licence record for old_aug)"
    assert "records no source corpus" in prov.trained_on[0].note
    assert provenance_from_corpus(aug, "adapters", source=corpus).weights_licence == "permissive (MIT)"
    (aug / SOURCE_CORPUS_NAME).write_text(json.dumps({"path": str(corpus)}))  # written by hand for an older run
    assert provenance_from_corpus(aug, "adapters").weights_licence == "permissive (MIT)"


def test_folder_without_manifest_is_unknown_said_plainly(tmp_path: Path) -> None:
    (tmp_path / "hml").mkdir()
    prov = provenance_from_corpus(tmp_path / "hml")
    assert prov.weights_licence.startswith("unknown") and "has no manifest.json" in prov.trained_on[0].note
    with pytest.raises(SimdiffError, match="not a data folder"):
        provenance_from_corpus(tmp_path / "missing")


def test_malformed_manifest_is_one_line(tmp_path: Path) -> None:
    (tmp_path / "c").mkdir()
    (tmp_path / "c" / "manifest.json").write_text("{not json")
    with pytest.raises(SimdiffError, match="manifest.json: cannot read JSON") as info:
        provenance_from_corpus(tmp_path / "c")
    assert "\n" not in str(info.value)
    write_manifest(tmp_path / "d", [clip("a_0", "CMU", 36.0), {"id": "b_0", "seconds": 1.0, "split": "train"}])
    assert "clip b_0" in provenance_from_corpus(tmp_path / "d").trained_on[0].note


def test_write_read_round_trip(tmp_path: Path) -> None:
    assert read_provenance(tmp_path) is None
    prov = Provenance([part("CMU"), part("CC-BY-NC-4.0", data="aug", what="adapters")])
    path = write_provenance(tmp_path, prov)
    assert path == tmp_path / PROVENANCE_NAME and [p.name for p in tmp_path.iterdir()] == [PROVENANCE_NAME]
    saved = json.loads(path.read_text())
    assert set(saved["licence_terms"]) == {"CMU", "CC-BY-NC-4.0"} and "non-commercial" in saved["weights_licence"]
    back = read_provenance(tmp_path)
    assert back is not None and back.to_dict() == prov.to_dict()


@pytest.mark.parametrize("text, needle", [
    ("{", "cannot read JSON"), ("[]", "expected an object with a 'trained_on' list"),
    ('{"trained_on": [{"what": "decoder", "data": "x"}]}', "what is 'decoder'"),
    ('{"trained_on": [{"data": "x"}]}', "must have 'what' and 'data'"),
    ('{"trained_on": [{"what": "backbone", "data": "x", "licences": {"CMU": "lots"}}]}', "licence codes to hours"),
    ('{"trained_on": [], "weights_licence": 3}', "weights_licence must be a string"),
])
def test_malformed_provenance_is_one_line(tmp_path: Path, text: str, needle: str) -> None:
    (tmp_path / PROVENANCE_NAME).write_text(text)
    with pytest.raises(SimdiffError, match=needle) as info:
        read_provenance(tmp_path)
    assert str(tmp_path / PROVENANCE_NAME) in str(info.value) and "\n" not in str(info.value)


def test_adapters_join_their_backbones_provenance(tmp_path: Path) -> None:
    corpus = write_manifest(tmp_path / "corpus", [clip("a_0", "CMU", 36.0), clip("n_0", "CC-BY-NC-4.0", 36.0)])
    backbone = tmp_path / "bb"
    write_provenance(backbone, training_provenance("backbone", [write_manifest(tmp_path / "cmu", [clip("a_0", "CMU", 36.0)])]))
    aug = write_augmented(tmp_path / "aug", ["n_0"], corpus)
    prov = training_provenance("adapters", [aug], init=backbone)
    assert [(p.what, p.data) for p in prov.trained_on] == [("backbone", "cmu"), ("adapters", "aug")]
    assert prov.weights_licence.startswith("non-commercial")
    # a whole SimDiff model as --init: only its backbone is loaded, so only its backbone entries carry over
    simdiff_folder = tmp_path / "simdiff"
    write_provenance(simdiff_folder, prov)
    again = training_provenance("adapters", [aug], init=simdiff_folder)
    assert [(p.what, p.data) for p in again.trained_on] == [("backbone", "cmu"), ("adapters", "aug")]
    (tmp_path / "bare").mkdir()
    bare = training_provenance("adapters", [aug], init=tmp_path / "bare")
    assert bare.trained_on[0].what == "backbone" and bare.weights_licence == "unknown (no licence record for bare)"
    synthetic = training_provenance("backbone", synthetic=4)
    assert synthetic.trained_on[0].data == "synthetic" and synthetic.weights_licence == "permissive (synthetic data only)"


def test_an_entry_listed_again_is_kept_once(tmp_path: Path) -> None:
    nc, cmu = part("CC-BY-NC-4.0", data="aug", what="adapters"), part("CMU")
    prov = Provenance([cmu, nc, part("CMU"), nc, part("CMU", data="aug", what="adapters")])
    assert prov.trained_on == [cmu, nc, part("CMU", data="aug", what="adapters")]  # order of first appearance
    assert prov.merged(Provenance([nc, cmu])).trained_on == prov.trained_on
    noted = TrainingData(what="backbone", data="corpus", licences={"CMU": 0.5}, note="a warm start")
    assert Provenance([cmu, noted]).trained_on == [cmu, noted]  # another note is another run: kept
    write_provenance(tmp_path, Provenance([cmu]))
    text = json.loads((tmp_path / PROVENANCE_NAME).read_text())
    text["trained_on"] *= 3  # a file written by an older version may repeat entries
    (tmp_path / PROVENANCE_NAME).write_text(json.dumps(text))
    back = read_provenance(tmp_path)
    assert back is not None and back.trained_on == [cmu]


def test_shipped_default_model_states_its_licence() -> None:
    from simdiff.inference.default import DEFAULT_MODEL_DIR

    prov = read_provenance(DEFAULT_MODEL_DIR)
    assert prov is not None and {p.what for p in prov.trained_on} == {"backbone", "adapters"}
    assert prov.weights_licence == weights_licence(prov.trained_on)  # the rule, not a hand-written label
    assert all(p.hours > 0 and p.licences for p in prov.trained_on)
    assert prov.weights_licence in (DEFAULT_MODEL_DIR / "README.md").read_text()
    import tomllib

    pyproject = tomllib.loads((Path(__file__).resolve().parent.parent / "pyproject.toml").read_text())
    assert "assets/**/*.json" in pyproject["tool"]["setuptools"]["package-data"]["simdiff"]


def test_cli_adapters_resumed_without_init_keep_the_backbone_entries(tmp_path: Path) -> None:
    import argparse

    from simdiff.cli.commands.train import _provenance

    corpus = write_manifest(tmp_path / "corpus", [clip("a_0", "CMU", 36.0)])
    aug = write_augmented(tmp_path / "aug", ["a_0"], corpus)
    args = argparse.Namespace(mode="adapters", data=[aug], split="train", source=None, synthetic=None, init=None,
                              out=tmp_path / "run")
    assert _provenance(args).trained_on[0].note == "licence unknown: resumed without --init"
    earlier = Provenance([part("MIT", data="cmu_corpus"), part("CMU", data="old_aug", what="adapters")])
    write_provenance(tmp_path / "run" / "model", earlier)
    resumed = _provenance(args)
    assert [(p.what, p.data) for p in resumed.trained_on] == [("backbone", "cmu_corpus"), ("adapters", "aug")]
    assert resumed.weights_licence == "permissive (CMU, MIT)"
