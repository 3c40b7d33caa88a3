"""BVH reader: forward kinematics on a synthetic file, units, errors, the CMU CC rig."""

from __future__ import annotations

import tarfile
from pathlib import Path

import numpy as np
import pytest

from simdiff.errors import MotionFormatError
from simdiff.motion.io.bvh import detect_scale, read_bvh, starts_with_tpose

BVH = """HIERARCHY
ROOT Hips
{
  OFFSET 0 0 0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
  JOINT Chest
  {
    OFFSET 0 10 0
    CHANNELS 3 Xrotation Yrotation Zrotation
    End Site
    {
      OFFSET 0 5 0
    }
  }
  JOINT Arm
  {
    OFFSET 10 0 0
    CHANNELS 6 Yrotation Xposition Yposition Zposition Zrotation Xrotation
    End Site
    {
      OFFSET 4 0 0
    }
  }
}
MOTION
Frames: 2
Frame Time: 0.0333333
0 0 0 0 0 0 0 0 0 0 10 20 30 0 0
100 50 0 90 0 0 90 0 0 90 20 0 0 90 0
"""


def _line(text: str, snippet: str) -> int:
    return text[: text.index(snippet)].count("\n") + 1


def _write(tmp_path: Path, text: str = BVH, name: str = "take.bvh") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def test_forward_kinematics_channel_orders(tmp_path: Path) -> None:
    rig = read_bvh(_write(tmp_path), scale=0.01)
    assert rig.names == ("Hips", "Chest", "Chest_End", "Arm", "Arm_End")
    assert rig.parents == (-1, 0, 1, 0, 3)
    assert rig.fps == pytest.approx(30.0, rel=1e-5)
    assert rig.positions.dtype == np.float32
    # frame 0: identity; the Arm's position channels replace its OFFSET
    expected0 = np.array([[0, 0, 0], [0, 10, 0], [0, 15, 0], [10, 20, 30], [14, 20, 30]]) * 0.01
    np.testing.assert_allclose(rig.positions[0], expected0, atol=1e-6)
    # frame 1: root Rz(90) moves the chest to -X; the chest's Rx(90) bends its end to +Z;
    # the arm's "Yrotation .. Zrotation Xrotation" is Ry @ Rz: +X -> +Y, then the root's
    # Rz(90) turns it to -X.
    expected1 = np.array([[100, 50, 0], [90, 50, 0], [90, 50, 5], [100, 70, 0], [96, 70, 0]]) * 0.01
    np.testing.assert_allclose(rig.positions[1], expected1, atol=1e-6)


def test_up_axis_and_drop_first(tmp_path: Path) -> None:
    rig = read_bvh(_write(tmp_path), scale=0.01, up="z", drop_first=True)
    assert rig.num_frames == 1
    # Z-up -> Y-up: (x, y, z) -> (x, z, -y)
    np.testing.assert_allclose(rig.joint("Chest_End")[0], [0.90, 0.05, -0.50], atol=1e-6)


def test_detect_scale() -> None:
    assert detect_scale(1.75) == 1.0
    assert detect_scale(172.0) == 0.01
    assert detect_scale(68.0) == 0.0254
    assert detect_scale(1750.0) == 0.001


def test_auto_scale_on_centimetre_rig(tmp_path: Path) -> None:
    text = BVH.replace("OFFSET 0 10 0", "OFFSET 0 150 0").replace("OFFSET 0 5 0", "OFFSET 0 20 0")
    rig = read_bvh(_write(tmp_path, text))
    assert rig.meta["scale"] == 0.01
    np.testing.assert_allclose(rig.joint("Chest_End")[0], [0.0, 1.7, 0.0], atol=1e-6)


def test_tpose_detection() -> None:
    t = np.arange(50) / 60.0
    walk = np.zeros((50, 3, 3))
    walk[..., 2] = t[:, None] * 1.2
    assert not starts_with_tpose(walk)
    walk[0] += [0.0, 0.0, 2.0]
    assert starts_with_tpose(walk)


_CASES = {
    "truncated": (BVH.rsplit("100 50", 1)[0], None, "truncated: Frames says 2 but 1"),
    "count": (BVH.replace("90 20 0 0 90 0", "90 20 0 0 90"), "100 50", "has 14 values"),
    "token": (BVH.replace("0 0 0 0 10 20", "0 0 0 0 1O 20"), "0 0 0 0 0 0 0 0 0", "non-numeric value '1O'"),
    "channel": (BVH.replace("Zrotation Xrotation Yrotation", "Zrotation Xrotation Wrotation"), "CHANNELS 6 X", "unknown channel 'Wrotation'"),
    "offset": (BVH.replace("OFFSET 10 0 0", "OFFSET 10 0"), "    CHANNELS 6 Y", "expected a number"),
    "brace": (BVH.replace("  JOINT Arm", "  JOINTS Arm"), "JOINTS", "unexpected 'JOINTS'"),
    "frames": (BVH.replace("Frames: 2", "Frames 2"), "Frames 2", "expected 'Frames:'"),
    "motion": (BVH[: BVH.index("MOTION")], None, "no MOTION section"),
    "empty": ("", None, "must start with HIERARCHY"),
}


@pytest.mark.parametrize("case", sorted(_CASES))
def test_malformed_files(tmp_path: Path, case: str) -> None:
    text, snippet, words = _CASES[case]
    path = _write(tmp_path, text, name="broken.bvh")
    with pytest.raises(MotionFormatError) as err:
        read_bvh(path, scale=1.0)
    message = str(err.value)
    assert "broken.bvh" in message and words in message
    assert "\n" not in message
    if snippet is not None:
        assert f"broken.bvh:{_line(text, snippet)}:" in message


@pytest.fixture(scope="module")
def cc_bvh(shared_data: Path, tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """Two CMU Character-Creator BVH files, read from the shared tar.xz into a temp dir."""
    want = {"bvh/02_01.bvh", "bvh/07_04.bvh"}
    out = tmp_path_factory.mktemp("cc_bvh")
    with tarfile.open(shared_data / "cmu" / "bvh.tar.xz", "r:xz") as archive:
        for member in archive:
            if member.name in want:
                archive.extract(member, out, filter="data")
                want.discard(member.name)
                if not want:
                    break
    return {p.stem: p for p in (out / "bvh").glob("*.bvh")}


def test_cc_rig_units_and_tpose(cc_bvh: dict[str, Path]) -> None:
    rig = read_bvh(cc_bvh["02_01"])
    assert rig.meta["scale"] == 0.01  # centimetres, detected
    assert len(rig.names) == 142  # 100 joints + 42 End Sites
    assert rig.fps == pytest.approx(60.0, rel=1e-3)
    assert rig.positions.shape == (171, 142, 3)
    pos = rig.positions.astype(np.float64)
    head = pos[:, rig.index("CC_Base_Head"), 1] - pos[:, :, 1].min(axis=1)
    assert 1.5 < np.median(head) < 1.75  # Y-up metres
    assert not starts_with_tpose(pos)

    posed = read_bvh(cc_bvh["07_04"])
    assert starts_with_tpose(posed.positions)
    dropped = read_bvh(cc_bvh["07_04"], drop_first=True)
    assert dropped.num_frames == posed.num_frames - 1
    assert not starts_with_tpose(dropped.positions)
