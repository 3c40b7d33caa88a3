"""Gait measures on synthetic walks and a standing body."""

from __future__ import annotations

import numpy as np
import pytest

from simdiff.motion.gait import foot_contacts, gait_measures
from simdiff.motion.synthetic import walk


def test_a_walk_travels_moves_its_limbs_and_steps() -> None:
    g = gait_measures(walk(81, speed=1.2, stride_hz=1.0))
    assert g["pelvis_speed"] == pytest.approx(1.2, rel=0.05)
    assert g["limb_speed"] > 0.3
    assert 60 <= g["cadence"] <= 150  # one stride per second: two steps, minus the first frame's
    assert 0.3 < g["duty_factor"] < 1.0


def test_a_frozen_pose_carried_along_has_pelvis_speed_but_no_limb_speed() -> None:
    still = walk(41, speed=0.0, amplitude=0.0, bounce=0.0)
    glide = still.copy()
    glide[:, :, 2] += np.arange(41)[:, None] * 0.05  # 1 m/s; relative to the pelvis only the arms' sway moves
    g = gait_measures(glide)
    assert g["pelvis_speed"] == pytest.approx(1.0, rel=1e-3)
    assert g["limb_speed"] == pytest.approx(gait_measures(still)["limb_speed"], abs=1e-4)  # carrying adds nothing
    assert g["cadence"] == 0.0 and g["duty_factor"] == 1.0
    assert foot_contacts(still).all()
