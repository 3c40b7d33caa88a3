"""ASF/AMC reader: forward kinematics on a tiny synthetic skeleton, errors, real CMU data."""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import pytest

from simdiff.errors import MotionFormatError
from simdiff.motion.io.asf_amc import find_asf, read_amc, read_asf

UNIT = 0.0254 / 0.45  # metres per ASF length unit with ":units length 0.45"

ASF = """# tiny test skeleton
:version 1.10
:name TEST
:units
  mass 1.0
  length 0.45
  angle deg
:root
   order TX TY TZ RX RY RZ
   axis XYZ
   position 0 0 0
   orientation 0 0 0
:bonedata
  begin
     id 1
     name femur
     direction 0 -1 0
     length 10
     axis 0 0 0  XYZ
    dof rx ry rz
    limits (-160.0 20.0)
           (-70.0 70.0)
           (-60.0 70.0)
  end
  begin
     id 2
     name tibia
     direction 0 -1 0
     length 9
     axis 0 90 0  XYZ
    dof rx
  end
  begin
     id 3
     name arm
     direction 1 0 0
     length 5
     axis 0 0 0  XYZ
    dof rz rx
  end
  begin
     id 4
     name hand
     direction 1 0 0
     length 2
     axis 0 0 0 XYZ
  end
:hierarchy
  begin
    root femur arm
    femur tibia
    arm hand
  end
"""

AMC = """#!OML:ASF test.asf
:FULLY-SPECIFIED
:DEGREES
1
root 0 45 0 0 0 0
femur 0 0 0
tibia 0
arm 0 0
2
root 45 45 0 0 90 0
femur 90 0 0
tibia 90
arm 90 90
"""


def _line(text: str, snippet: str) -> int:
    """1-based line of the first occurrence of ``snippet`` in ``text``."""
    return text[: text.index(snippet)].count("\n") + 1


def _write(tmp_path: Path, asf: str = ASF, amc: str = AMC) -> tuple[Path, Path]:
    (tmp_path / "asf").mkdir(exist_ok=True)
    (tmp_path / "amc").mkdir(exist_ok=True)
    asf_path = tmp_path / "asf" / "07.asf"
    amc_path = tmp_path / "amc" / "07_01.amc"
    asf_path.write_text(asf)
    amc_path.write_text(amc)
    return asf_path, amc_path


def test_asf_units_and_hierarchy(tmp_path: Path) -> None:
    asf_path, _ = _write(tmp_path)
    skel = read_asf(asf_path)
    assert skel.order == ["root", "femur", "arm", "tibia", "hand"]
    assert skel.bones["femur"].length == pytest.approx(10 * UNIT)  # 0.56444 m
    assert skel.bones["tibia"].dofs == ("rx",)
    assert skel.bones["arm"].dofs == ("rz", "rx")


def test_amc_forward_kinematics(tmp_path: Path) -> None:
    asf_path, amc_path = _write(tmp_path)
    rig = read_amc(amc_path, asf_path, fps=60)
    assert rig.fps == 60.0
    assert rig.positions.dtype == np.float32
    assert rig.names == ("root", "femur", "arm", "tibia", "hand")
    assert rig.parents == (-1, 0, 0, 1, 2)
    f, t, a, h = 10 * UNIT, 9 * UNIT, 5 * UNIT, 2 * UNIT
    p0 = rig.positions[0].astype(np.float64)
    root0 = np.array([0.0, 45 * UNIT, 0.0])  # 2.54 m: translation uses the length unit
    np.testing.assert_allclose(p0[0], root0, atol=1e-6)
    np.testing.assert_allclose(p0[1], root0 + [0, -f, 0], atol=1e-6)
    np.testing.assert_allclose(p0[3], root0 + [0, -f - t, 0], atol=1e-6)
    np.testing.assert_allclose(p0[4], root0 + [a + h, 0, 0], atol=1e-6)

    # frame 2: root turned 90 deg about Y (x -> -z, z -> x); femur rx 90 swings the thigh
    # to -Z; the tibia's frame C = Ry(90) makes its rx a rotation about -Z (shin -> -X);
    # the arm's "dof rz rx" applies rz first: +X -> +Y -> +Z.
    p1 = rig.positions[1].astype(np.float64)
    root1 = np.array([45 * UNIT, 45 * UNIT, 0.0])
    ry90 = np.array([[0, 0, 1], [0, 1, 0], [-1, 0, 0]], dtype=float)
    knee_local = np.array([0, 0, -f])
    tibia_local = np.array([-t, 0.0, 0.0])  # Rx(90) @ Rz(-90) @ (0,-1,0) * t
    arm_local = np.array([0.0, 0.0, a + h])
    np.testing.assert_allclose(p1[0], root1, atol=1e-6)
    np.testing.assert_allclose(p1[1], root1 + ry90 @ knee_local, atol=1e-6)
    np.testing.assert_allclose(p1[3], root1 + ry90 @ (knee_local + tibia_local), atol=1e-6)
    np.testing.assert_allclose(p1[4], root1 + ry90 @ arm_local, atol=1e-6)
    # numbers spelled out: ankle at (2.54 - 0.5644, 2.54, 0.508), hand at x = 2.54 + 0.3951
    np.testing.assert_allclose(p1[3], [1.975556, 2.54, 0.508], atol=1e-5)
    assert p1[4, 0] == pytest.approx(2.54 + 0.395111, abs=1e-5)


def test_find_asf_sibling_folder(tmp_path: Path) -> None:
    asf_path, amc_path = _write(tmp_path)
    assert find_asf(amc_path) == asf_path
    assert find_asf(tmp_path / "amc" / "99_01.amc") is None


_AMC_CASES = {
    "count": (AMC.replace("tibia 90\n", "tibia 90 3\n"), "tibia 90 3", "2 values"),
    "text": (AMC.replace("arm 90 90\n", "arm 90 x\n"), "arm 90 x", "non-numeric"),
    "bone": (AMC.replace("femur 90 0 0\n", "leg 90 0 0\n"), "leg 90", "unknown bone"),
    "missing": (AMC.replace("arm 90 90\n", ""), "2\nroot", "lacks 1 bone"),
    "order": (AMC.replace("2\nroot", "3\nroot"), "3\nroot", "does not follow"),
    "nan": (AMC.replace("0 0 90 0", "0 0 nan 0"), "root 45", "non-finite"),
}


@pytest.mark.parametrize("case", sorted(_AMC_CASES))
def test_amc_errors_name_file_and_line(tmp_path: Path, case: str) -> None:
    amc, snippet, words = _AMC_CASES[case]
    line = _line(amc, snippet)
    asf_path, amc_path = _write(tmp_path, amc=amc)
    with pytest.raises(MotionFormatError) as err:
        read_amc(amc_path, asf_path)
    message = str(err.value)
    assert f"07_01.amc:{line}:" in message
    assert words in message
    assert "\n" not in message


def test_truncated_amc_mid_line(tmp_path: Path) -> None:
    asf_path, amc_path = _write(tmp_path, amc=AMC[: AMC.index("tibia 90") + 5])
    with pytest.raises(MotionFormatError, match=r"07_01\.amc:12: bone 'tibia' has 0 values"):
        read_amc(amc_path, asf_path)


_ASF_CASES = {
    "child": (ASF.replace("    femur tibia\n", "    femur shin\n"), "femur shin", "unknown bone 'shin'"),
    "length": (ASF.replace("     length 9\n", "     length nine\n"), "length nine", "non-numeric length"),
    "dof": (ASF.replace("    dof rx\n", "    dof rx l\n"), "dof rx l", "unsupported dof 'l'"),
    "orphan": (ASF.replace("    arm hand\n", ""), "begin\n     id 4", "not connected"),
    "no_hierarchy": (ASF[: ASF.index(":hierarchy")], None, "no :hierarchy"),
}


@pytest.mark.parametrize("case", sorted(_ASF_CASES))
def test_asf_errors(tmp_path: Path, case: str) -> None:
    asf, snippet, words = _ASF_CASES[case]
    line = _line(asf, snippet) if snippet else None
    asf_path, amc_path = _write(tmp_path, asf=asf)
    with pytest.raises(MotionFormatError) as err:
        read_amc(amc_path, asf_path)
    message = str(err.value)
    assert "07.asf" in message and words in message
    if line is not None:
        assert f"07.asf:{line}:" in message


def test_real_cmu_walk(shared_data: Path) -> None:
    cmu = shared_data / "cmu"
    start = time.perf_counter()
    rig = read_amc(cmu / "amc" / "02_01.amc", cmu / "asf" / "02.asf")
    elapsed = time.perf_counter() - start
    assert rig.positions.shape == (343, 34, 3)  # 31 bones + 3 sites
    assert elapsed < 2.0
    pos = rig.positions.astype(np.float64)
    # Y-up, metres: feet near the floor, top of the head-bone ~1.55-1.65 m
    feet = pos[:, [rig.index("ltoes"), rig.index("rtoes")], 1].min(axis=1)
    assert np.median(feet) == pytest.approx(0.03, abs=0.03)
    head = np.median(pos[:, rig.index("head"), 1])
    assert 1.5 < head < 1.7
    # a walk: the root moves ~1 m/s horizontally
    speed = np.linalg.norm(pos[-1, 0, [0, 2]] - pos[0, 0, [0, 2]]) / (343 / 120)
    assert 0.8 < speed < 1.8
    # bone lengths are constant
    femur = np.linalg.norm(pos[:, rig.index("lfemur")] - pos[:, rig.index("lhipjoint")], axis=-1)
    assert femur.std() < 1e-5 and 0.38 < femur.mean() < 0.48


HEAD_ASF = """:version 1.10
:name HEAD
:units
  length 0.45
  angle deg
:root
   order TX TY TZ RX RY RZ
   axis XYZ
   position 0 0 0
   orientation 0 0 0
:bonedata
  begin
     id 1
     name head
     direction 0 1 0
     length 10
     axis 0 0 0  XYZ
    dof rx
  end
:hierarchy
  begin
    root head
  end
"""

HEAD_AMC = """:FULLY-SPECIFIED
:DEGREES
1
root 0 0 0 0 0 0
head 0
2
root 0 0 0 0 0 0
head 90
"""


def test_head_centre_site_moves_with_the_head(tmp_path: Path) -> None:
    from simdiff.motion.io.asf_amc import ASF_SITES

    asf_path, amc_path = _write(tmp_path, HEAD_ASF, HEAD_AMC)
    rig = read_amc(amc_path, asf_path)
    assert rig.names == ("root", "head", "head_centre")  # clavicle sites skipped: no such bones
    assert rig.parents == (-1, 0, 1)
    length = 10 * UNIT
    left, up, forward = dict((s[0], s[2]) for s in ASF_SITES)["head_centre"]
    # no hip bones: rest frame left +X, up +Y, forward +Z; offset from the bone's end
    rest = np.array([0.0, length, 0.0]) + length * np.array([left, up, forward])
    np.testing.assert_allclose(rig.positions[0, 2], rest, atol=1e-6)
    # rx 90: the head (and the site) rotate about X: (x, y, z) -> (x, -z, y)
    rot = np.array([[1.0, 0, 0], [0, 0, -1], [0, 1, 0]])
    np.testing.assert_allclose(rig.positions[1, 2], rot @ rest, atol=1e-6)
    # the site is below the top of the head and in front of the head bone
    assert up < 0 < forward
