"""CMU corpus loading details: T-pose detection, DeepMimic ground clean-up, support flag."""

from __future__ import annotations

import numpy as np
import pytest

from simdiff.data.clip_files import CONTACT_HEIGHT, ground_contact, support_of
from simdiff.data.corpus.cmu_load import read_source_rig, source_frame
from simdiff.data.corpus.cmu_sources import Trial
from simdiff.motion.io.ground import MAX_LIFT, lift_penetrations


def _standing(frames: int = 60, height: float = 0.0) -> np.ndarray:
    """(T, 22, 3) joints: a column from ``height`` to ``height`` + 1.7 m."""
    joints = np.zeros((frames, 22, 3))
    joints[..., 1] = height + np.linspace(0.0, 1.7, 22)[None, :]
    return joints


def test_lift_penetrations_removes_short_dips() -> None:
    joints = _standing()
    joints[30:32, :, 1] -= 0.04  # a 2-frame, 4 cm dip below the ground
    out = lift_penetrations(joints)
    lowest = out[..., 1].min(axis=-1)
    assert out.dtype == np.float32 and lowest.min() == pytest.approx(0.0, abs=1e-6)
    # the clip stands on the floor again (before: the floor sat 4 cm below 58 of 60 frames)
    assert np.median(lowest) == pytest.approx(0.0, abs=1e-6)
    # frames far from the dip are unchanged apart from the common shift
    np.testing.assert_allclose(out[:20], joints[:20], atol=1e-6)


def test_lift_penetrations_caps_deep_dips() -> None:
    joints = _standing()
    joints[30:33, :, 1] -= 0.5  # a real drop (e.g. into a pit): lifted by MAX_LIFT at most
    out = lift_penetrations(joints)
    lift = out[31, 0, 1] - (joints[31, 0, 1] - joints[..., 1].min())
    assert lift <= MAX_LIFT + 1e-6


def test_ground_contact_and_support() -> None:
    standing = _standing(40)
    hanging = _standing(40, height=0.4)
    hanging[:5] = _standing(5)  # touches the ground only at the start
    assert ground_contact(standing) == 1.0 and support_of(ground_contact(standing)) == "floor"
    assert ground_contact(hanging) == pytest.approx(5 / 40)
    assert support_of(ground_contact(hanging)) == "props"
    jump = _standing(40)
    jump[10:25, :, 1] += 0.3  # airborne 15 of 40 frames: still a floor clip
    assert support_of(ground_contact(jump)) == "floor"
    assert CONTACT_HEIGHT > 0.1


def _bvh(tpose: bool) -> str:
    lines = ["HIERARCHY", "ROOT Hips", "{", "  OFFSET 0 0 0", "  CHANNELS 3 Xposition Yposition Zposition",
             "  JOINT Head", "  {", "    OFFSET 0 60 0", "    CHANNELS 3 Zrotation Xrotation Yrotation",
             "    End Site", "    {", "      OFFSET 0 10 0", "    }", "  }", "}"]
    rows = [f"{0.5 * k:.3f} 95 0 0 0 0" for k in range(30)]
    if tpose:
        rows.insert(0, "0 95 80 0 0 0")  # an added rest frame far from frame 1
    return "\n".join(lines + ["MOTION", f"Frames: {len(rows)}", "Frame Time: 0.016667", *rows]) + "\n"


@pytest.mark.parametrize("tpose", [True, False])
def test_bvh_tpose_dropped_only_when_present(tmp_path, tpose: bool) -> None:  # type: ignore[no-untyped-def]
    path = tmp_path / "02_01.bvh"
    path.write_text(_bvh(tpose))
    trial = Trial(trial="02_01", files={"bvh": path})
    rig, skipped = read_source_rig(trial, "bvh")
    assert skipped == (1 if tpose else 0)
    assert rig.num_frames == 30
    np.testing.assert_allclose(rig.positions[0, 0, 0], 0.0, atol=1e-6)  # first real frame kept
    assert source_frame(trial, "bvh", 20, skipped) == 60 + skipped
