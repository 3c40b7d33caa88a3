"""Inverse kinematics on the rigid skeleton: given coordinates met, bones exact, neighbours bent, free joints held."""

from __future__ import annotations

import numpy as np
import pytest

from simdiff.motion import synthetic
from simdiff.motion.reach import reach
from simdiff.motion.rigid import bone_lengths, fit
from simdiff.motion.skeleton import UPPER_BODY


@pytest.fixture(scope="module")
def walk():
    motion = fit(synthetic.walk(80).astype(np.float64), None)
    return motion, motion.joints.astype(np.float64)


def _error(joints: np.ndarray, keys: np.ndarray) -> float:
    return float(np.abs(np.where(np.isfinite(keys), joints - np.nan_to_num(keys), 0.0)).max())


def test_a_lone_wrist_is_met_and_its_neighbours_bend_smoothly(walk) -> None:
    motion, before = walk
    keys = np.full_like(before, np.nan)
    keys[40, 20] = before[40, 20] + [0.10, 0.10, 0.05]  # 15 cm off, within the arm's reach
    after = reach(motion, keys).joints
    assert _error(after, keys) < 0.003
    assert np.ptp(bone_lengths(after), axis=0).max() < 1e-5  # the same bones
    step = np.linalg.norm(np.diff(after[:, 20], axis=0), axis=-1) * 20  # wrist speed, m/s
    step_before = np.linalg.norm(np.diff(before[:, 20], axis=0), axis=-1) * 20
    assert step.max() < step_before.max() + 1.0  # bent over the neighbours, not a one-frame jump
    assert np.linalg.norm(after[38:43, 20] - before[38:43, 20], axis=-1).min() > 0.03  # the frames around it move too
    assert np.linalg.norm(after[:, [7, 8, 10, 11]] - before[:, [7, 8, 10, 11]], axis=-1).max() < 0.01  # feet stay


def test_a_kept_upper_body_and_a_root_path_are_met(walk) -> None:
    motion, before = walk
    keys = np.full_like(before, np.nan)
    keys[:, list(UPPER_BODY)] = before[:, list(UPPER_BODY)] + [0.0, 0.0, 0.04]
    assert _error(reach(motion, keys).joints, keys) < 0.003
    path = np.full_like(before, np.nan)
    path[::20, 0, 0] = before[::20, 0, 0] + 0.1  # x alone: y and z stay free
    after = reach(motion, path).joints
    assert _error(after, path) < 0.003
    assert np.abs(after[::20, 0, 1] - before[::20, 0, 1]).max() < 0.01


def test_nothing_given_changes_nothing_and_shapes_are_checked(walk) -> None:
    motion, before = walk
    assert reach(motion, np.full_like(before, np.nan)) is motion
    assert reach(motion, before) is motion  # everything given is already met: nothing to solve
    with pytest.raises(ValueError, match="targets must be"):
        reach(motion, np.zeros((3, 22, 3)))


@pytest.mark.parametrize(("frame", "joint"), [(40, 20), (0, 7)])
def test_an_unreachable_target_is_neared_without_a_jump(walk, frame: int, joint: int) -> None:
    motion, before = walk
    keys = np.full_like(before, np.nan)
    keys[frame, joint] = before[frame, joint] + [2.0, 0.0, 3.0]  # metres from the body
    after = reach(motion, keys).joints
    assert np.isfinite(after).all() and np.ptp(bone_lengths(after), axis=0).max() < 1e-5
    assert np.linalg.norm(after[frame, joint] - keys[frame, joint]) < np.linalg.norm(before[frame, joint] - keys[frame, joint])
    # neared, not met by teleporting: the pull stops growing beyond REACH. It still speeds the nearest joints up (18
    # against 4.3 m/s for the ankle at frame 0); with a quadratic pull and no acceleration term it was 61 m/s
    speed = np.linalg.norm(np.diff(after, axis=0), axis=-1) * 20
    assert speed.max() < 5 * (np.linalg.norm(np.diff(before, axis=0), axis=-1) * 20).max()
