"""``simdiff data build-cmu`` / ``report`` end to end on a tiny synthetic CMU source folder.

The folder holds an ASF/AMC pair (CMU bone names, 60 fps), a BVH with common biped names
(cm, first frame an added T-pose), a DeepMimic JSON, a truncated AMC, a manifest with a
KIT-ML caption and HumanML3D segments, and HumanML3D split files.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import numpy as np
import pytest

from simdiff.cli.main import main
from simdiff.data.cmu.build import BuildConfig, build_corpus
from simdiff.data.humanml3d import HumanML3D, read_captions
from simdiff.motion.kinematics import facing_direction
from simdiff.motion.skeleton import FACE_JOINTS

# name, parent, direction (x left, y up, z forward), length in ASF units (0.45 in)
_BONES = [
    ("lhipjoint", "root", (0.66, -0.71, 0.25), 2.5), ("lfemur", "lhipjoint", (0.34, -0.94, 0), 7.6),
    ("ltibia", "lfemur", (0.34, -0.94, 0), 7.6), ("lfoot", "ltibia", (0.09, -0.24, 0.97), 2.2),
    ("ltoes", "lfoot", (0, 0, 1), 1.1),
    ("rhipjoint", "root", (-0.66, -0.71, 0.25), 2.5), ("rfemur", "rhipjoint", (-0.34, -0.94, 0), 7.6),
    ("rtibia", "rfemur", (-0.34, -0.94, 0), 7.6), ("rfoot", "rtibia", (-0.09, -0.24, 0.97), 2.2),
    ("rtoes", "rfoot", (0, 0, 1), 1.1),
    ("lowerback", "root", (0, 1, -0.07), 2.0), ("upperback", "lowerback", (0, 1, 0.01), 2.0),
    ("thorax", "upperback", (0, 1, 0.02), 2.0), ("lowerneck", "thorax", (0, 1, 0.04), 1.5),
    ("upperneck", "lowerneck", (0, 1, -0.02), 1.5), ("head", "upperneck", (0, 1, 0.01), 1.5),
    ("lclavicle", "thorax", (0.9, 0.4, -0.1), 3.5), ("lhumerus", "lclavicle", (1, 0, 0), 5.0),
    ("lradius", "lhumerus", (1, 0, 0), 3.3), ("lwrist", "lradius", (1, 0, 0), 1.7),
    ("lhand", "lwrist", (1, 0, 0), 0.7), ("lfingers", "lhand", (1, 0, 0), 0.6),
    ("lthumb", "lwrist", (0.7, 0, 0.7), 0.8),
    ("rclavicle", "thorax", (-0.9, 0.4, -0.1), 3.5), ("rhumerus", "rclavicle", (-1, 0, 0), 5.0),
    ("rradius", "rhumerus", (-1, 0, 0), 3.3), ("rwrist", "rradius", (-1, 0, 0), 1.7),
    ("rhand", "rwrist", (-1, 0, 0), 0.7), ("rfingers", "rhand", (-1, 0, 0), 0.6),
    ("rthumb", "rwrist", (-0.7, 0, 0.7), 0.8),
]


def _asf() -> str:
    lines = [":version 1.10", ":name SYN", ":units", "  mass 1.0", "  length 0.45", "  angle deg",
             ":root", "   order TX TY TZ RX RY RZ", "   axis XYZ", "   position 0 0 0", "   orientation 0 0 0",
             ":bonedata"]
    for i, (name, _, direction, length) in enumerate(_BONES, start=1):
        lines += ["  begin", f"     id {i}", f"     name {name}", "     direction " + " ".join(map(str, direction)),
                  f"     length {length}", "     axis 0 0 0 XYZ", "    dof rx ry rz", "  end"]
    lines += [":hierarchy", "  begin"]
    children: dict[str, list[str]] = {}
    for name, parent, _, _ in _BONES:
        children.setdefault(parent, []).append(name)
    lines += [f"    {parent} {' '.join(kids)}" for parent, kids in children.items()]
    lines += ["  end"]
    return "\n".join(lines) + "\n"


def _amc(seconds: float, fps: int, turn: float = 0.0) -> str:
    """A walk: root forward at 1.2 m/s (yawing ``turn`` rad/s), thighs and arms swinging."""
    unit = 0.0254 / 0.45
    lines = [":FULLY-SPECIFIED", ":DEGREES"]
    for k in range(int(seconds * fps)):
        t = k / fps
        swing = 25 * np.sin(2 * np.pi * t)
        yaw = turn * t
        x, z = (0.0, 1.2 * t) if turn == 0 else (1.2 / turn * (1 - np.cos(yaw)), 1.2 / turn * np.sin(yaw))
        lines.append(str(k + 1))
        lines.append(f"root {x / unit:.4f} {0.93 / unit:.4f} {z / unit:.4f} 0 {np.degrees(yaw):.4f} 0")
        for name, *_ in _BONES:
            rx = {"lfemur": -swing, "rfemur": swing, "ltibia": max(0.0, swing), "rtibia": max(0.0, -swing)}.get(name, 0.0)
            rz = {"lhumerus": -70.0, "rhumerus": 70.0}.get(name, 0.0)
            lines.append(f"{name} {rx:.4f} 0 {rz:.4f}")
    return "\n".join(lines) + "\n"


_BVH_JOINTS = [  # name, parent, offset in cm
    ("Hips", None, (0, 95, 0)), ("LeftUpLeg", "Hips", (9, -5, 0)), ("LeftLeg", "LeftUpLeg", (0, -42, 0)),
    ("LeftFoot", "LeftLeg", (0, -41, 0)), ("LeftToeBase", "LeftFoot", (0, -5, 12)),
    ("RightUpLeg", "Hips", (-9, -5, 0)), ("RightLeg", "RightUpLeg", (0, -42, 0)),
    ("RightFoot", "RightLeg", (0, -41, 0)), ("RightToeBase", "RightFoot", (0, -5, 12)),
    ("Spine", "Hips", (0, 10, 0)), ("Spine1", "Spine", (0, 12, 0)), ("Spine2", "Spine1", (0, 12, 0)),
    ("Neck", "Spine2", (0, 16, 0)), ("Head", "Neck", (0, 10, 0)),
    ("LeftShoulder", "Spine2", (4, 12, 0)), ("LeftArm", "LeftShoulder", (14, 0, 0)),
    ("LeftForeArm", "LeftArm", (26, 0, 0)), ("LeftHand", "LeftForeArm", (25, 0, 0)),
    ("RightShoulder", "Spine2", (-4, 12, 0)), ("RightArm", "RightShoulder", (-14, 0, 0)),
    ("RightForeArm", "RightArm", (-26, 0, 0)), ("RightHand", "RightForeArm", (-25, 0, 0)),
]


def _bvh(seconds: float, fps: int) -> str:
    """Biped BVH in cm: a T-pose frame, then a walk forward with swinging legs."""
    names = [j[0] for j in _BVH_JOINTS]
    lines = ["HIERARCHY"]

    def emit(index: int, depth: int) -> None:
        name, parent, offset = _BVH_JOINTS[index]
        pad = "  " * depth
        lines.append(f"{pad}{'ROOT' if parent is None else 'JOINT'} {name}")
        lines.append(pad + "{")
        lines.append(f"{pad}  OFFSET {offset[0]} {offset[1]} {offset[2]}")
        channels = "6 Xposition Yposition Zposition Zrotation Xrotation Yrotation" if parent is None else "3 Zrotation Xrotation Yrotation"
        lines.append(f"{pad}  CHANNELS {channels}")
        kids = [i for i, j in enumerate(_BVH_JOINTS) if j[1] == name]
        for kid in kids:
            emit(kid, depth + 1)
        if not kids:
            lines.extend([f"{pad}  End Site", pad + "  {", f"{pad}    OFFSET 0 0 5", pad + "  }"])
        lines.append(pad + "}")

    emit(0, 0)
    frames = int(seconds * fps)
    lines += ["MOTION", f"Frames: {frames + 1}", f"Frame Time: {1 / fps:.6f}"]
    lines.append(" ".join(["0", "95", "0"] + ["0"] * (3 * len(names))))  # the added T-pose
    for k in range(frames):
        t = k / fps
        swing = 25 * np.sin(2 * np.pi * t)
        values = [0.0, 95.0, 120.0 * t + 30.0]  # root jumps 30 cm after the T-pose
        for name in names:
            rot = {"LeftUpLeg": swing, "RightUpLeg": -swing, "LeftArm": -70.0, "RightArm": 70.0}.get(name, 0.0)
            values += [rot if name.endswith("Arm") else 0.0, 0.0 if name.endswith("Arm") else rot, 0.0]
        lines.append(" ".join(f"{v:.4f}" for v in values))
    return "\n".join(lines) + "\n"


def _deepmimic(seconds: float, fps: int) -> str:
    frames = []
    for k in range(int(seconds * fps)):
        t = k / fps
        row = [1.0 / fps, 1.0 * t, 0.85, 0.0, 1.0, 0.0, 0.0, 0.0]  # walks along +X (its forward)
        half = 0.2 * np.sin(2 * np.pi * t)
        hip = [float(np.cos(half)), 0.0, 0.0, float(np.sin(half))]
        hip_l = [float(np.cos(-half)), 0.0, 0.0, float(np.sin(-half))]
        ident = [1.0, 0.0, 0.0, 0.0]
        # chest, neck, r hip, r knee, r ankle, r shoulder, r elbow, l hip, l knee, l ankle, l shoulder, l elbow
        row += ident + ident + hip + [0.0] + ident + ident + [0.0] + hip_l + [0.0] + ident + ident + [0.0]
        frames.append(row)
    return json.dumps({"Loop": "none", "Frames": frames})


@pytest.fixture(scope="module")
def source(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("shared")
    src = root / "cmu"
    for sub in ("amc", "asf", "bvh", "deepmimic"):
        (src / sub).mkdir(parents=True)
    (src / "asf" / "01.asf").write_text(_asf())
    (src / "amc" / "01_01.amc").write_text(_amc(3.0, 60, turn=0.4))
    (src / "amc" / "01_02.amc").write_text(_amc(12.0, 60))
    truncated = _amc(3.0, 60)
    (src / "amc" / "01_03.amc").write_text(truncated[: len(truncated) // 2].rsplit("\n", 3)[0] + "\nlfemur 1 2\n")
    (src / "bvh" / "02_01.bvh").write_text(_bvh(3.0, 60))
    (src / "deepmimic" / "03_01.txt").write_text(_deepmimic(3.0, 30))
    bvh = _bvh(3.0, 60)
    (src / "bvh" / "04_01.bvh").write_text(bvh[: len(bvh) // 2])  # truncated mid-frames
    (src / "deepmimic" / "05_01.txt").write_text('{"Loop": "none", "Frames": [[0.03, 1, 2')  # broken JSON
    (src / "CMU_data.csv").write_text(
        '"Subject","Trial #","Motion Description","framerate"\n'
        + "".join(f'{s},{t},"x",60\n' for s, t in ((1, 1), (1, 2), (1, 3), (2, 1), (3, 1)))
    )
    rows = [
        {"trial": "01_01", "cmu_desc": "walk, veer left", "kitml": [],
         "hml3d_segments": [{"hml_id": "000100", "start20": 5, "end20": 55}]},
        {"trial": "01_02", "cmu_desc": "walk", "hml3d_segments": [],
         "kitml": [{"kit_id": "1", "text": "A person walks forward steadily.", "start": 0.0, "end": 12.0}]},
        {"trial": "01_03", "cmu_desc": "walk", "kitml": [], "hml3d_segments": []},
        {"trial": "02_01", "cmu_desc": "slow walk", "kitml": [], "hml3d_segments": []},
        {"trial": "03_01", "cmu_desc": "jump", "kitml": [], "hml3d_segments": []},
    ]
    (src / "manifest.jsonl").write_text("".join(json.dumps(r) + "\n" for r in rows))
    splits = root / "humanml3d" / "splits"
    splits.mkdir(parents=True)
    (splits / "test.txt").write_text("000100\n")
    (splits / "train.txt").write_text("")
    return src


@pytest.fixture(scope="module")
def corpus(source: Path, tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, object]:
    out = tmp_path_factory.mktemp("corpus")
    result = build_corpus(BuildConfig(src=source, out=out, seed=0, progress=False))
    return out, result


def _tree_digest(root: Path) -> dict[str, str]:
    return {
        str(p.relative_to(root)): hashlib.sha1(p.read_bytes()).hexdigest()
        for p in sorted(root.rglob("*")) if p.is_file() and ".build" not in p.parts
    }


def test_build_writes_humanml3d_layout(corpus: tuple[Path, object]) -> None:
    out, result = corpus
    manifest = json.loads((out / "manifest.json").read_text())
    clips = {c["id"]: c for c in manifest["clips"]}
    assert {c["trial"] for c in clips.values()} == {"01_01", "01_02", "02_01", "03_01"}
    assert {c["rig"] for c in clips.values()} == {"amc", "bvh", "deepmimic"}
    skipped = {s["trial"]: s["error"] for s in manifest["skipped"]}
    assert set(skipped) == {"01_03", "04_01", "05_01"}  # bad files are reported, the build goes on
    assert "01_03.amc" in skipped["01_03"] and "04_01.bvh" in skipped["04_01"] and "05_01.txt" in skipped["05_01"]
    for cid, clip in clips.items():
        feats = np.load(out / "new_joint_vecs" / f"{cid}.npy")
        joints = np.load(out / "new_joints" / f"{cid}.npy")
        assert feats.dtype == np.float32 and feats.shape[1] == 263 and 40 <= len(feats) <= 196
        assert joints.dtype == np.float32 and joints.shape == (len(feats), 22, 3)
        assert clip["frames"] == len(feats) and clip["source"] and clip["caption_origin"] in ("kitml", "generated")
        assert abs(joints[..., 1].min()) < 0.02  # on the floor
        forward = facing_direction(joints[:1].astype(np.float64), FACE_JOINTS)[0]
        assert forward[2] > 0.999  # facing +Z at frame 0
        assert np.all(joints[:, 15, 1] > joints[:, 0, 1])  # upright
        assert read_captions(out / "texts" / f"{cid}.txt")
    assert clips["01_01_00"]["window"] == "hml3d:000100"
    assert (clips["01_01_00"]["start20"], clips["01_01_00"]["stop20"]) == (5, 55)
    assert len([c for c in clips.values() if c["trial"] == "01_02"]) == 4  # 12 s: 2 windows + mirrors
    assert all(c["mirror_of"] is None or c["id"] == "M" + c["mirror_of"] for c in clips.values())


def test_captions_human_generated_and_mirrored(corpus: tuple[Path, object]) -> None:
    out, _ = corpus
    kit = read_captions(out / "texts" / "01_02_00.txt")
    assert [c.text for c in kit] == ["A person walks forward steadily."]
    generated = read_captions(out / "texts" / "01_01_00.txt")
    assert len(generated) == 3 and generated[0].text == "a person walks forward and veers to the left."
    assert all("/" in tok for c in generated for tok in c.tokens)
    mirrored = read_captions(out / "texts" / "M01_01_00.txt")
    assert mirrored[0].text == "a person walks forward and veers to the right."
    # the walk turns left (+X): the mirror turns right
    assert np.load(out / "new_joints" / "01_01_00.npy")[-1, 0, 0] > 0.1
    assert np.load(out / "new_joints" / "M01_01_00.npy")[-1, 0, 0] < -0.1


def test_splits_by_trial_and_stats(corpus: tuple[Path, object]) -> None:
    out, _ = corpus
    split_of: dict[str, str] = {}
    for split in ("train", "val", "test"):
        for cid in (out / f"{split}.txt").read_text().split():
            trial = cid.lstrip("M").rsplit("_", 1)[0]
            assert split_of.setdefault(trial, split) == split  # never in two splits
    assert split_of["01_01"] == "test"  # its HumanML3D segment is in the test split
    all_ids = set((out / "all.txt").read_text().split())
    assert all_ids == {p.stem for p in (out / "new_joint_vecs").glob("*.npy")}
    mean, std = np.load(out / "Mean.npy"), np.load(out / "Std.npy")
    assert mean.shape == std.shape == (263,) and mean.dtype == np.float32 and np.all(std > 0)
    assert np.allclose(std[67:193], std[67])  # grouped std (HumanML3D)


def test_loader_reads_the_corpus_unchanged(corpus: tuple[Path, object]) -> None:
    out, _ = corpus
    data = HumanML3D(out, "all", seed=0)
    assert len(data) > 0
    item = data[0]
    assert item["motion"].shape == (196, 263) and item["caption"] and item["length"] >= 40


def test_rebuild_is_incremental_and_idempotent(source: Path, tmp_path: Path) -> None:
    out = tmp_path / "c"
    first = build_corpus(BuildConfig(src=source, out=out, seed=0, progress=False))
    before = _tree_digest(out)
    second = build_corpus(BuildConfig(src=source, out=out, seed=0, progress=False))
    assert second.processed == 0 and second.reused == first.processed
    assert _tree_digest(out) == before
    # an interrupted trial (record lost) is redone; nothing else is
    (out / ".build" / "trials" / "02_01.json").unlink()
    third = build_corpus(BuildConfig(src=source, out=out, seed=0, progress=False))
    assert third.processed == 1 and _tree_digest(out) == before
    # fewer sources: the clips that are no longer built are removed
    fourth = build_corpus(BuildConfig(src=source, out=out, seed=0, progress=False, rigs=("amc", "bvh")))
    assert not any(c["rig"] == "deepmimic" for c in fourth.clips)
    assert not (out / "new_joint_vecs" / "03_01_00.npy").exists()


def test_cli_build_and_report(source: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "c"
    assert main(["data", "build-cmu", "--src", str(source), "--out", str(out), "--quiet", "--trials", "01_01", "03_01"]) == 0
    assert "0 skipped" in capsys.readouterr().out
    report = tmp_path / "report"
    assert main(["data", "report", str(out), "--out", str(report), "--no-crosscheck"]) == 0
    text = (report / "report.md").read_text()
    assert "## Per split" in text and "## Physics metrics" in text
    assert (report / "summary.png").stat().st_size > 1000
    assert list(report.glob("filmstrip_*.png"))
    assert main(["data", "build-cmu", "--src", str(tmp_path / "nope"), "--out", str(out)]) == 2
    assert "source folder not found" in capsys.readouterr().err
    assert main(["data", "build-cmu", "--src", str(source), "--out", str(out), "--trials", "99_99"]) == 2


def test_real_cmu_trials(shared_data: Path, tmp_path: Path) -> None:
    src = shared_data / "cmu"
    result = build_corpus(BuildConfig(src=src, out=tmp_path / "c", trials=["02_01", "13_19", "35_18"], progress=False))
    rigs = {c["trial"]: c["rig"] for c in result.clips}
    assert rigs == {"02_01": "amc", "13_19": "amc"}
    assert [s["trial"] for s in result.skipped] == ["35_18"]  # subject 35 has no ASF here
    walk = np.load(tmp_path / "c" / "new_joints" / "02_01_00.npy")
    assert 2.0 < walk[-1, 0, 2] < 4.5  # walks ~3 m forward (+Z) in ~3 s
    assert np.median(walk[:, [7, 8, 10, 11], 1].min(axis=1)) < 0.05  # a foot on the floor


def test_manifest_support_flag(corpus: tuple[Path, object]) -> None:
    out, _ = corpus
    clips = json.loads((out / "manifest.json").read_text())["clips"]
    assert clips and all(c["support"] in ("floor", "props") for c in clips)
    assert all(0.0 <= c["ground_contact"] <= 1.0 for c in clips)
    # the synthetic walks stay on the ground
    assert {c["support"] for c in clips if c["rig"] == "amc"} == {"floor"}
