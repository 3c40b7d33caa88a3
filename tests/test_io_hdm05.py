"""HDM05 ASF/AMC: per-actor ``HDM_<actor>.asf`` beside ``HDM_<actor>_<motion>_<take>_120.amc``,
Latin-1 text, ASF length unit 0.45 (as CMU), 120 fps (synthetic files + one real take)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from mocap_fixtures import extra_member

from simdiff.motion.io import find_asf, load_joints, load_rig
from simdiff.motion.io.asf_amc import amc_fps_from_name
from simdiff.motion.io.retarget import CMU_ASF_MAP, joint_map_for
from simdiff.motion.skeleton import JOINT_NAMES

J = JOINT_NAMES.index
UNIT = 0.0254 / 0.45

# (bone, parent, direction, length in ASF units, dofs): a straight standing CMU-type body
BONES = [
    ("lhipjoint", "root", (0.6, -0.8, 0.0), 2.4, ""),
    ("lfemur", "lhipjoint", (0.0, -1.0, 0.0), 7.3, "rx ry rz"),
    ("ltibia", "lfemur", (0.0, -1.0, 0.0), 7.0, "rx"),
    ("lfoot", "ltibia", (0.0, -0.45, 0.9), 2.2, "rx rz"),
    ("ltoes", "lfoot", (0.0, 0.0, 1.0), 1.1, "rx"),
    ("rhipjoint", "root", (-0.6, -0.8, 0.0), 2.4, ""),
    ("rfemur", "rhipjoint", (0.0, -1.0, 0.0), 7.3, "rx ry rz"),
    ("rtibia", "rfemur", (0.0, -1.0, 0.0), 7.0, "rx"),
    ("rfoot", "rtibia", (0.0, -0.45, 0.9), 2.2, "rx rz"),
    ("rtoes", "rfoot", (0.0, 0.0, 1.0), 1.1, "rx"),
    ("lowerback", "root", (0.0, 1.0, 0.0), 2.0, "rx ry rz"),
    ("upperback", "lowerback", (0.0, 1.0, 0.0), 2.0, "rx ry rz"),
    ("thorax", "upperback", (0.0, 1.0, 0.0), 2.0, "rx ry rz"),
    ("lowerneck", "thorax", (0.0, 1.0, 0.0), 1.7, "rx ry rz"),
    ("upperneck", "lowerneck", (0.0, 1.0, 0.0), 1.7, "rx ry rz"),
    ("head", "upperneck", (0.0, 1.0, 0.0), 1.8, "rx ry rz"),
    ("lclavicle", "thorax", (0.95, 0.3, 0.0), 3.4, "ry rz"),
    ("lhumerus", "lclavicle", (1.0, 0.0, 0.0), 5.5, "rx ry rz"),
    ("lradius", "lhumerus", (1.0, 0.0, 0.0), 3.6, "rx"),
    ("lwrist", "lradius", (1.0, 0.0, 0.0), 1.8, "ry"),
    ("rclavicle", "thorax", (-0.95, 0.3, 0.0), 3.4, "ry rz"),
    ("rhumerus", "rclavicle", (-1.0, 0.0, 0.0), 5.5, "rx ry rz"),
    ("rradius", "rhumerus", (-1.0, 0.0, 0.0), 3.6, "rx"),
    ("rwrist", "rradius", (-1.0, 0.0, 0.0), 1.8, "ry"),
]
ROOT_Y = 0.8 * 2.4 + 7.3 + 7.0 + 0.45 * 2.2  # the toes touch y = 0


def _asf() -> str:
    lines = ["# AST/ASF file generated using VICON BodyLanguage", "# Aufnahme für Bonn",
             ":version 1.10", ":name VICON", ":units", "  mass 1.0", "  length 0.45", "  angle deg",
             ":root", "   order TX TY TZ RX RY RZ", "   axis XYZ", "   position 0 0 0",
             "   orientation 0 0 0", ":bonedata"]
    for k, (name, _, direction, length, dofs) in enumerate(BONES, start=1):
        lines += ["  begin", f"     id {k}", f"     name {name}",
                  f"     direction {direction[0]} {direction[1]} {direction[2]}",
                  f"     length {length}", "     axis 0 0 0  XYZ"]
        if dofs:
            lines.append(f"    dof {dofs}")
        lines.append("  end")
    lines += [":hierarchy", "  begin"]
    parents: dict[str, list[str]] = {}
    for name, parent, *_ in BONES:
        parents.setdefault(parent, []).append(name)
    lines += [f"    {p} {' '.join(kids)}" for p, kids in parents.items()]
    lines.append("  end")
    return "\r\n".join(lines) + "\r\n"


def _amc(frames: int) -> str:
    lines = ["#!OML:ASF X:\\für Bonn\\!DataBase\\Bastian.ASF", ":FULLY-SPECIFIED", ":DEGREES"]
    for f in range(1, frames + 1):
        lines.append(str(f))
        lines.append(f"root 0 {ROOT_Y} {0.1 * f} 0 0 0")
        for name, _, _, _, dofs in BONES:
            if dofs:
                lines.append(f"{name} " + " ".join("0" for _ in dofs.split()))
    return "\r\n".join(lines) + "\r\n"


def _write(tmp_path: Path, frames: int = 24) -> Path:
    folder = tmp_path / "train" / "3"
    folder.mkdir(parents=True)
    (folder / "HDM_bd.asf").write_bytes(_asf().encode("latin-1"))
    amc = folder / "HDM_bd_kickLFront1Reps_001_120.amc"
    amc.write_bytes(_amc(frames).encode("latin-1"))
    return amc


def test_hdm05_asf_found_rate_units(tmp_path: Path) -> None:
    amc = _write(tmp_path)
    assert find_asf(amc) == amc.parent / "HDM_bd.asf"
    assert amc_fps_from_name(amc) == 120.0
    assert amc_fps_from_name(tmp_path / "07_60.amc") is None  # a CMU trial number, not a rate
    rig = load_rig(amc)
    assert rig.fps == 120.0
    assert joint_map_for(rig) is CMU_ASF_MAP  # HDM05 bones are CMU's
    joints = load_joints(amc)
    assert joints.shape == (4, 22, 3) and joints.dtype == np.float32
    leg = np.linalg.norm(joints[:, J("left_hip")] - joints[:, J("left_ankle")], axis=-1)
    np.testing.assert_allclose(leg, 14.3 * UNIT, atol=1e-4)  # ASF units -> metres as CMU
    assert joints[..., 1].min() == pytest.approx(0.0, abs=1e-6)
    np.testing.assert_allclose(joints[:, J("left_foot"), 1], 0.0, atol=1e-4)
    # 0.1 unit per frame forward at 120 fps
    assert np.diff(joints[:, 0, 2]).mean() * 20 == pytest.approx(0.1 * UNIT * 120, rel=1e-3)


def test_hdm05_placement(tmp_path: Path) -> None:
    j = load_joints(_write(tmp_path))[0].astype(np.float64)
    hips = 0.5 * (j[J("left_hip")] + j[J("right_hip")])
    np.testing.assert_allclose(j[J("pelvis")], hips + 0.15 * (j[J("neck")] - hips), atol=1e-5)
    heights = [j[J(n), 1] for n in ("pelvis", "spine1", "spine2", "spine3", "neck", "head")]
    assert np.all(np.diff(heights) > 0)
    assert j[J("head"), 2] > j[J("neck"), 2] + 0.03  # the head joint in front of the neck
    assert 1.4 < j[J("head"), 1] < 1.9


def test_real_hdm05_take(shared_data: Path, tmp_path: Path) -> None:
    def actor_asf(name: str) -> str:
        folder, stem = name.rsplit("/", 1)
        return f"{folder}/{'_'.join(stem.split('_')[:2])}.asf"

    amc = extra_member(shared_data, "hdm05.tar.xz", tmp_path, lambda n: n.endswith(".amc"), actor_asf)
    assert find_asf(amc) is not None
    rig = load_rig(amc)
    assert rig.fps == 120.0
    joints = load_joints(amc)
    leg = np.linalg.norm(joints[:, J("left_hip")] - joints[:, J("left_ankle")], axis=-1).mean()
    assert 0.7 < leg < 1.0
    assert joints[..., 1].min() == pytest.approx(0.0, abs=1e-6)
