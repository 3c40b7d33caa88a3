"""The prompt-following detectors on synthetic motions whose answer is known."""

from __future__ import annotations

import numpy as np
import pytest

from simdiff.errors import SimdiffError
from simdiff.eval.detectors import parse_check, run_check, standing_height
from simdiff.eval.stats import wilson_interval
from simdiff.motion.synthetic import jump, walk


def passes(joints: np.ndarray, check: str, reference: np.ndarray | None = None) -> bool:
    return run_check(joints, check, reference).passed


def test_direction_reads_travel_in_the_body_frame() -> None:
    ahead, back = walk(80, speed=1.2), walk(80, speed=-1.0)
    assert passes(ahead, "direction:forward") and not passes(ahead, "direction:backward")
    assert passes(back, "direction:backward") and not passes(back, "direction:forward")
    turned_around = np.concatenate([ahead, ahead[-1:] + (ahead[::-1] - ahead[-1:]) * [1, 1, 1]])  # walks back facing ahead
    assert run_check(turned_around, "travel:return").passed
    side = ahead.copy()
    side[..., 0], side[..., 2] = ahead[..., 0] + ahead[:, :1, 2] - ahead[0, 0, 2], ahead[..., 2] - ahead[:, :1, 2]
    assert passes(side, "direction:left") and not passes(side, "direction:right")  # slides towards +X facing +Z


def test_turns_and_circles() -> None:
    left = walk(80, turn_rate=1.0)  # 229° to the left in 4 s
    assert passes(left, "turn:left") and passes(left, "turn:around") and not passes(left, "turn:right")
    assert passes(walk(80, turn_rate=-1.0), "turn:right")
    assert passes(walk(196, turn_rate=2 * np.pi / 9.0), "circle:")  # a full circle in 9 s
    assert not passes(walk(196), "circle:") and not passes(walk(196, turn_rate=0.3), "circle:")


def test_counts_and_staying_in_place() -> None:
    one = jump(60, airtime=0.5)
    assert passes(one, "count:jumps=1") and not passes(one, "count:jumps=2")
    assert passes(np.concatenate([one, one]), "count:jumps=2")
    assert passes(one, "travel:in_place") and not passes(one, "travel:away")
    assert passes(walk(80), "travel:away") and not passes(walk(80), "travel:in_place")
    assert passes(walk(80, speed=1.2), "count:jumps=0")  # walking never leaves the floor


def test_body_side_posture_and_order() -> None:
    still = walk(60, speed=0.0, amplitude=0.0, bounce=0.0).astype(np.float64)
    raised = still.copy()
    raised[20:40, 20, 1] = still[0, 15, 1] + 0.1  # the left wrist above the head
    assert passes(raised, "side:arm=left") and not passes(raised, "side:arm=right")
    kicked = still.copy()
    kicked[20:30, 8, 1] += 0.5  # the right ankle
    assert passes(kicked, "side:leg=right") and not passes(kicked, "side:leg=left")
    squat = still.copy()
    stand = standing_height(still)
    squat[20:40, 0, 1] = 0.6 * stand
    assert passes(squat, "posture:crouch") and passes(squat, "posture:sit_stand") and not passes(squat, "posture:sit")
    assert passes(squat, "count:squats=1") and not passes(still, "posture:crouch")
    brief = still.copy()
    brief[20:25, 0, 1] = 0.6 * stand  # a quarter-second dip: a squat's bottom, not a seat
    assert passes(brief, "posture:crouch") and not passes(brief, "posture:sit_stand")
    hover = still.copy()
    hover[20:24, 0, 1] = hover[26:30, 0, 1] = 0.7 * stand  # down, just over the threshold for 0.1 s, down again
    hover[24:26, 0, 1] = 0.76 * stand
    assert run_check(hover, "count:squats=1").passed
    hop = jump(60, airtime=0.5, start=40).astype(np.float64)
    walked = walk(60, speed=1.2).astype(np.float64)
    both = np.concatenate([walked, hop + (walked[-1, 0] - hop[0, 0]) * [1, 0, 1]])
    assert passes(both, "order:travel<jump") and not passes(both, "order:jump<travel")


def test_speed_is_paired_with_its_reference() -> None:
    slow, plain = walk(80, speed=0.6), walk(80, speed=1.2)
    assert passes(slow, "speed:slower", plain) and passes(plain, "speed:faster", slow)
    assert not passes(plain, "speed:slower", plain)
    standing = walk(80, speed=0.0)
    verdict = run_check(standing, "speed:slower", plain)
    assert not verdict.passed and "no pace" in verdict.reading  # ignoring the prompt by standing still is no pass
    with pytest.raises(SimdiffError, match="needs a reference motion"):
        run_check(plain, "speed:slower")


@pytest.mark.parametrize("bad", ["direction:up", "turn", "count:jumps=two", "order:jump<jump", "side:leg=middle",
                                 "nonsense", "circle:x", "order:sit<crouch"])
def test_a_bad_check_is_one_line_naming_it(bad: str) -> None:
    with pytest.raises(SimdiffError) as err:
        parse_check(bad)
    assert repr(bad) in str(err.value) and "\n" not in str(err.value)


def test_non_finite_motions_are_refused() -> None:
    broken = walk(40).astype(np.float64)
    broken[10, 3, 1] = np.nan
    with pytest.raises(SimdiffError, match="NaN"):
        run_check(broken, "count:jumps=0")


def test_wilson_interval() -> None:
    assert wilson_interval(0, 10) == pytest.approx((0.0, 0.2775), abs=1e-4)
    assert wilson_interval(5, 10) == pytest.approx((0.2366, 0.7634), abs=1e-4)
    with pytest.raises(SimdiffError):
        wilson_interval(3, 2)
