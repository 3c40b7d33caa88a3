"""CMU corpus helpers without motion data: captions, POS tokens, windows, trial names, joint agreement."""

from __future__ import annotations

import pytest

from simdiff.data.corpus.cmu_captions import caption_line, describe, motion_type, split_camel
from simdiff.data.corpus.pos import tag, tokens
from simdiff.data.corpus.cmu_sources import Segment, normalise_trial
from simdiff.data.corpus.windows import MAX_WINDOW, MIN_WINDOW, plan_windows
from simdiff.data.humanml3d import read_captions
from simdiff.motion.mirror import mirror_caption


def test_describe_reads_like_a_caption() -> None:
    out = describe("run/jog, veer left", n=3, seed=0, key="16_38_00")
    assert len(out) == 3 and len(set(out)) == 3
    for sentence in out:
        assert sentence.endswith(".") and sentence == sentence.lower()
        assert "left" in sentence and ("jog" in sentence or "run" in sentence)
    assert describe("run/jog, veer left", seed=1, key="x")[0] == "a person jogs forward and veers to the left."


def test_describe_is_deterministic_and_seeded() -> None:
    a = describe("basketball - forward dribble, 90-degree left turns", seed=3, key="06_10_00")
    assert a == describe("basketball - forward dribble, 90-degree left turns", seed=3, key="06_10_00")
    many = {tuple(describe("walk", seed=s, key="k")) for s in range(6)}
    assert len(many) > 1


@pytest.mark.parametrize(
    "description",
    ["TooCoolWalk", "dance - coupe dessous, jete en tourant", "180", "jumping jacks, side twists",
     "Get Up Face Down", "some unheard-of motion", "", "playground - climb, sit"],
)
def test_describe_never_fails(description: str) -> None:
    out = describe(description, n=2)
    assert 1 <= len(out) <= 2
    assert all(s.split()[0] in ("a", "someone", "the") for s in out)


def test_mirrored_generated_caption_swaps_side() -> None:
    sentence = describe("walk, veer left", n=1)[0]
    assert "right" in mirror_caption(sentence) and "left" not in mirror_caption(sentence)


def test_motion_type_and_camel_case() -> None:
    assert split_camel("TooCoolWalk") == "too cool walk"
    assert motion_type("run/jog, veer left") == "run"
    assert motion_type("dance - expressive arms, pirouette") == "dance"
    assert motion_type("JumpTwist") == "jump"
    assert motion_type("basketball - forward dribble") == "sports"
    assert motion_type("cartwheel") == "acrobatics"
    assert motion_type("zzz") == "other"


def test_pos_tokens_in_humanml3d_format() -> None:
    assert tokens("A man kicks something with his left leg.") == (
        "a/DET man/NOUN kick/VERB something/PRON with/ADP his/DET left/ADJ leg/NOUN"
    )
    lemmas = dict(tag("someone is walking and turns to the right"))
    assert lemmas["walk"] == "VERB" and lemmas["be"] == "AUX" and lemmas["right"] == "NOUN"


def test_caption_line_is_read_back(tmp_path) -> None:
    path = tmp_path / "x.txt"
    path.write_text(caption_line("a person jumps # twice.") + "\n")
    (caption,) = read_captions(path)
    assert caption.text == "a person jumps twice."
    assert caption.tokens[:3] == ("a/DET", "person/NOUN", "jump/VERB")
    assert caption.whole


def test_windows_use_segments_and_cover_the_rest() -> None:
    windows = plan_windows(460, [Segment("b", 19, 219), Segment("a", 201, 401), Segment("tiny", 0, 10)])
    assert [(w.start, w.stop, w.origin) for w in windows] == [
        (19, 19 + MAX_WINDOW, "hml3d:b"), (201, 201 + MAX_WINDOW, "hml3d:a"), (398, 460, "even")]
    for w in plan_windows(1000):
        assert MIN_WINDOW <= w.frames <= MAX_WINDOW and w.origin == "even"
    assert sum(w.frames for w in plan_windows(1000)) == 1000
    assert plan_windows(MIN_WINDOW - 1) == []


def test_trial_names() -> None:
    assert normalise_trial("2_1") == "02_01"
    assert normalise_trial("105_23") == "105_23"
    assert normalise_trial("humanoid3d_run") is None


def test_compare_joints_recovers_lag_and_rotation() -> None:
    import numpy as np

    from simdiff.data.corpus.joint_agreement import compare_joints
    from simdiff.motion.synthetic import walk

    a = walk(120, turn_rate=0.3).astype(np.float64)
    yaw = np.radians(30.0)
    rot = np.array([[np.cos(yaw), 0, np.sin(yaw)], [0, 1, 0], [-np.sin(yaw), 0, np.cos(yaw)]])
    b = a[3:] @ rot.T + np.array([1.0, 0.02, -2.0])  # b starts 3 frames later
    result = compare_joints(a, b, fps=20.0, trial="t")
    assert result.lag_s == pytest.approx(3 / 20)
    assert result.mpjpe < 1e-6 and result.root_relative < 1e-6
    assert abs(abs(result.yaw_deg) - 30.0) < 1e-4
    noisy = compare_joints(a, a + np.random.default_rng(0).normal(scale=0.01, size=a.shape), fps=20.0)
    assert 0.005 < noisy.mpjpe < 0.03
