"""``simdiff data build`` / ``report`` on a small fake shared tree the tests write themselves.

The tree holds one CMU trial three times (ASF/AMC, BVH, DeepMimic: dedupe keeps the AMC),
an extra CMU trial as Motionbuilder-style BVH, an acLSTM dance, six Bandai-style BVH (cm,
``joint_Root`` + game-rig names, json labels, cfg label files), an HDM05-style ASF/AMC pair
packed as ``extra/hdm05.tar.xz``, and one DeepMimic clip present twice with the same bytes.
"""

from __future__ import annotations

import hashlib
import json
import tarfile
from pathlib import Path

import numpy as np
import pytest

from simdiff.cli.main import main
from simdiff.data.corpus.build import CorpusConfig, build
from simdiff.licences import LICENCE_SETS
from simdiff.data.corpus.registry import discover_all
from simdiff.data.corpus.splits import assign_stratified
from simdiff.data.humanml3d import read_captions
from mocap_fixtures import POS_ROT, bvh_text
from cmu_fixtures import amc_text, asf_text, cmu_bvh_text, deepmimic_text

_BANDAI = [  # name, parent, offset (cm): the Bandai game rig's joint names
    ("joint_Root", None, (0, 0, 0)), ("Hips", "joint_Root", (0, 95, 0)),
    ("Spine", "Hips", (0, 15, 0)), ("Chest", "Spine", (0, 15, 0)), ("Neck", "Chest", (0, 20, 0)),
    ("Head", "Neck", (0, 10, 0)),
    ("Shoulder_L", "Chest", (4, 16, 0)), ("UpperArm_L", "Shoulder_L", (14, 0, 0)),
    ("LowerArm_L", "UpperArm_L", (26, 0, 0)), ("Hand_L", "LowerArm_L", (25, 0, 0)),
    ("Shoulder_R", "Chest", (-4, 16, 0)), ("UpperArm_R", "Shoulder_R", (-14, 0, 0)),
    ("LowerArm_R", "UpperArm_R", (-26, 0, 0)), ("Hand_R", "LowerArm_R", (-25, 0, 0)),
    ("UpperLeg_L", "Hips", (9, -5, 0)), ("LowerLeg_L", "UpperLeg_L", (0, -42, 0)),
    ("Foot_L", "LowerLeg_L", (0, -41, 0)), ("Toes_L", "Foot_L", (0, -5, 12)),
    ("UpperLeg_R", "Hips", (-9, -5, 0)), ("LowerLeg_R", "UpperLeg_R", (0, -42, 0)),
    ("Foot_R", "LowerLeg_R", (0, -41, 0)), ("Toes_R", "Foot_R", (0, -5, 12)),
]


def _bandai_bvh(seconds: float, speed: float, fps: int = 30) -> str:
    """A Bandai-style BVH in cm: static ``joint_Root``, ``Hips`` moving forward with swinging legs."""
    joints = [(name, parent, offset, POS_ROT) for name, parent, offset in _BANDAI]
    leaves = {name: (0.0, 0.0, 0.0) for name, _, _ in _BANDAI if all(p != name for _, p, _ in _BANDAI)}
    rows = []
    for k in range(int(seconds * fps)):
        t = k / fps
        swing = 25 * np.sin(2 * np.pi * t * max(speed, 1.0))
        values: list[float] = []
        for name, _, offset in _BANDAI:
            pos = list(offset)
            if name == "Hips":
                pos = [offset[0], offset[1], offset[2] + 100.0 * speed * t]
            rot = {"UpperLeg_L": swing, "UpperLeg_R": -swing}.get(name, 0.0)
            values += pos + [0.0, rot, 0.0]
        rows.append(values)
    return bvh_text(joints, np.asarray(rows), round(1 / fps, 6), leaves)


@pytest.fixture(scope="module")
def shared(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("shared")
    cmu = root / "cmu"
    for sub in ("amc", "asf", "bvh", "deepmimic/extra"):
        (cmu / sub).mkdir(parents=True)
    (cmu / "asf" / "01.asf").write_text(asf_text())
    (cmu / "amc" / "01_01.amc").write_text(amc_text(3.0, 60))
    (cmu / "bvh" / "01_01.bvh").write_text(cmu_bvh_text(3.0, 60))  # the same trial as BVH
    (cmu / "deepmimic" / "01_01.txt").write_text(deepmimic_text(3.0, 30))  # ... and as DeepMimic
    (cmu / "CMU_data.csv").write_text('"Subject","Trial #","Motion Description","framerate"\n1,1,"walk",60\n'
                                      '2,1,"jump",60\n')
    (cmu / "descriptions.tsv").write_text("01_01\twalk\n02_01\tjump up and down\n")
    (cmu / "manifest.jsonl").write_text(json.dumps({"trial": "01_01", "cmu_desc": "walk", "hml3d_segments": [],
                                                    "kitml": []}) + "\n")
    extra = root / "extra"
    (extra / "cmu-bvh" / "motionbuilder").mkdir(parents=True)
    (extra / "cmu-bvh" / "motionbuilder" / "02_01.bvh").write_text(cmu_bvh_text(2.5, 60))
    (extra / "cmu-bvh" / "aclstm" / "salsa").mkdir(parents=True)
    (extra / "cmu-bvh" / "aclstm" / "salsa" / "01.bvh").write_text(cmu_bvh_text(2.5, 60))
    data = extra / "bandai-namco" / "dataset" / "Bandai-Namco-Research-Motiondataset-1"
    (data / "cfg").mkdir(parents=True)
    (data / "data").mkdir()
    (data / "cfg" / "content_label.txt").write_text("dataset-1_walk-left\ndataset-1_run\n")
    (data / "cfg" / "style_label.txt").write_text("dataset-1_old\ndataset-1_active\ndataset-1_normal\n")
    for c, content in enumerate(("walk-left", "run")):
        for s, style in enumerate(("old", "active", "normal")):
            stem = f"dataset-1_{content}_{style}_001"
            (data / "data" / f"{stem}.bvh").write_text(_bandai_bvh(2.5, 1.0 + c))
            (data / "data" / f"{stem}.json").write_text(json.dumps({"content": c, "style": s}))
    hdm = tmp_path_factory.mktemp("hdm") / "hdm05" / "train" / "4"
    hdm.mkdir(parents=True)
    (hdm / "HDM_bd.asf").write_text(asf_text())
    (hdm / "HDM_bd_hopBothLegs1hops_001_120.amc").write_text(amc_text(1.5, 120))  # 1.5 s: padded to 2 s
    with tarfile.open(extra / "hdm05.tar.xz", "w:xz") as tar:
        tar.add(hdm.parent.parent, arcname="hdm05")
    motions = extra / "deepmimic-xbpeng" / "data" / "motions"
    motions.mkdir(parents=True)
    jump = deepmimic_text(2.5, 30)
    (motions / "humanoid3d_jump.txt").write_text(jump)
    (cmu / "deepmimic" / "extra" / "humanoid3d_jump.txt").write_text(jump)  # same bytes
    (motions / "humanoid3d_jump_mirror.txt").write_text(deepmimic_text(2.4, 30))  # left out
    return root


@pytest.fixture(scope="module")
def corpus(shared: Path, tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, object]:
    out = tmp_path_factory.mktemp("corpus")
    return out, build(CorpusConfig(shared=shared, out=out, workers=1, progress=False))


def _tree_digest(root: Path) -> dict[str, str]:
    return {str(p.relative_to(root)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(root.rglob("*")) if p.is_file() and ".build" not in p.parts}


def test_discovery_dedupes_copies_and_hashes(shared: Path, tmp_path: Path) -> None:
    items = {i.id: i for i in discover_all(shared, tmp_path)}
    assert items["01_01"].source == "cmu-amc"
    assert sorted(a.source for a in items["01_01"].alternates) == ["cmu-bvh", "cmu-deepmimic"]
    assert items["02_01"].source == "cmu-mb"
    dm = [i for i in items.values() if i.source == "deepmimic"]
    assert [i.id for i in dm] == ["dm_jump"]  # two equal files, the mirror file left out
    assert len([i for i in items.values() if i.source == "bandai"]) == 6
    hop = items["hdm_bd_hopBothLegs1hops_001"]
    assert (hop.licence, hop.motion_type, hop.fps) == ("CC-BY-SA-3.0", "jump", 120.0)
    assert items["bn1_walk-left_old_001"].licence == "CC-BY-NC-4.0"
    permissive = discover_all(shared, tmp_path, licence="permissive")
    assert {i.licence for i in permissive} <= LICENCE_SETS["permissive"]
    assert {i.source for i in permissive} == {"cmu-amc", "cmu-mb", "cmu-aclstm", "deepmimic"}


def test_every_clip_has_captions_and_a_licence(corpus: tuple[Path, object]) -> None:
    out, _ = corpus
    manifest = json.loads((out / "manifest.json").read_text())
    clips = manifest["clips"]
    assert {c["source"] for c in clips} == {"cmu-amc", "cmu-mb", "cmu-aclstm", "bandai", "hdm05", "deepmimic"}
    for clip in clips:
        assert clip["licence"] in LICENCE_SETS["all"]
        assert len(clip["captions"]) >= 2 and len(set(clip["captions"])) == len(clip["captions"])
        assert not any(ch in s for s in clip["captions"] for ch in "{}<>#"), clip["captions"]
        lines = read_captions(out / "texts" / f"{clip['id']}.txt")
        assert len(lines) >= 2
        for key in ("trial", "motion_type", "caption_origin", "file", "fps", "frames", "seconds", "split"):
            assert clip[key] not in (None, ""), (clip["id"], key)
    left = next(c for c in clips if c["id"] == "bn1_walk-left_old_001_00")
    assert any("left" in s for s in left["captions"])
    mirror = next(c for c in clips if c["id"] == "Mbn1_walk-left_old_001_00")
    assert any("right" in s for s in mirror["captions"]) and not any("left" in s for s in mirror["captions"])
    hop = next(c for c in clips if c["id"] == "hdm_bd_hopBothLegs1hops_001_00")
    assert hop["padded_frames"] > 0 and hop["frames"] == 40
    assert hop["source_frames"] == [0, 180]  # 1.5 s at 120 fps: the held frames map to the take's ends
    assert np.load(out / "new_joint_vecs" / "hdm_bd_hopBothLegs1hops_001_00.npy").shape == (40, 263)
    assert manifest["counts"]["hours_originals_by_licence"].keys() == {"CMU", "CC-BY-NC-4.0", "CC-BY-SA-3.0", "MIT"}
    assert next(c for c in clips if c["id"] == "01_01_00")["alternates"]


def test_splits_group_trials_and_stratify() -> None:
    durations = {f"t{i}": 10.0 for i in range(12)}
    strata = {f"t{i}": ("a/jump" if i < 4 else "b/walk") for i in range(12)}
    split = assign_stratified(durations, strata, {"t0": "train"}, seed=3)
    for label in ("a/jump", "b/walk"):
        got = {split[t] for t, s in strata.items() if s == label}
        assert got == {"train", "val", "test"}
    assert split["t0"] == "train"
    assert assign_stratified(durations, strata, seed=3) == assign_stratified(durations, strata, seed=3)


def test_corpus_splits_keep_trials_and_mirrors_together(corpus: tuple[Path, object]) -> None:
    out, _ = corpus
    clips = json.loads((out / "manifest.json").read_text())["clips"]
    by_id = {c["id"]: c for c in clips}
    trial_split: dict[str, str] = {}
    for clip in clips:
        assert trial_split.setdefault(clip["trial"], clip["split"]) == clip["split"]
        if clip["mirror_of"]:
            assert by_id[clip["mirror_of"]]["split"] == clip["split"]
    listed = {name: set((out / f"{name}.txt").read_text().split()) for name in ("train", "val", "test")}
    assert set().union(*listed.values()) == set(by_id)
    bandai = {c["split"] for c in clips if c["source"] == "bandai" and c["motion_type"] == "run"}
    assert bandai == {"train", "val", "test"}  # a stratum of 3 trials is in every split
    assert np.load(out / "Mean.npy").shape == (263,) and np.all(np.load(out / "Std.npy") > 0)


def test_rebuild_is_byte_identical_across_worker_counts(shared: Path, corpus: tuple[Path, object],
                                                        tmp_path: Path) -> None:
    out, _ = corpus
    other = tmp_path / "w2"
    result = build(CorpusConfig(shared=shared, out=other, workers=2, progress=False))
    assert result.processed > 0
    assert _tree_digest(other) == _tree_digest(out)


def test_resume_after_interruption(shared: Path, corpus: tuple[Path, object], tmp_path: Path) -> None:
    import shutil

    out, _ = corpus
    copy = tmp_path / "resume"
    shutil.copytree(out, copy)
    # as if killed while processing one item: its record and one of its files are gone, no manifest
    (copy / ".build" / "items" / "bn1_run_old_001.json").unlink()
    (copy / "new_joints" / "bn1_run_old_001_00.npy").unlink()
    (copy / "manifest.json").unlink()
    result = build(CorpusConfig(shared=shared, out=copy, workers=1, progress=False))
    assert result.processed == 1 and result.reused >= 10
    assert _tree_digest(copy) == _tree_digest(out)


def test_cli_permissive_build_and_report(shared: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "perm"
    assert main(["data", "build", "--shared", str(shared), "--out", str(out), "--licence", "permissive",
                 "--workers", "1", "--quiet"]) == 0
    printed = capsys.readouterr().out
    assert "hours (original) by licence: CMU" in printed and "CC-BY-NC" not in printed
    clips = json.loads((out / "manifest.json").read_text())["clips"]
    assert {c["licence"] for c in clips} <= {"CMU", "MIT"}
    report_dir = tmp_path / "report"
    assert main(["data", "report", str(out), "--out", str(report_dir)]) == 0
    text = (report_dir / "report.md").read_text()
    for heading in ("Hours by licence", "Hours by source", "Flight", "Physics metrics per source",
                    "Dedupe cross-checks", "cmu-amc vs cmu-bvh", "Filmstrips"):
        assert heading in text, heading
    assert (report_dir / "filmstrip_cmu-amc.png").is_file() and (report_dir / "clip_metrics.csv").is_file()


def test_bad_options_are_one_line_errors(shared: Path, tmp_path: Path) -> None:
    from simdiff.errors import SimdiffError

    with pytest.raises(SimdiffError, match="licence"):
        build(CorpusConfig(shared=shared, out=tmp_path / "x", licence="commercial", progress=False))
    with pytest.raises(SimdiffError, match="not found"):
        build(CorpusConfig(shared=tmp_path / "missing", out=tmp_path / "y", progress=False))


def test_flight_counts_airborne_frames() -> None:
    """The corpus report counts flights with the shared rule (simdiff.motion.flight) on real frames."""
    from simdiff.data.corpus.report import _flight

    stand = np.zeros((40, 22, 3), dtype=np.float32)
    stand[..., 1] = np.linspace(0.0, 1.6, 22)  # lowest joints on the floor
    stand[:, [7, 8], 1] = 0.08
    stand[:, [10, 11], 1] = 0.0
    assert _flight(stand) == {"flight_s": 0.0, "longest_flight_s": 0.0}
    jump = stand.copy()
    jump[10:16, :, 1] += 0.3  # 6 frames = 0.3 s in the air
    jump[30:32, :, 1] += 0.3  # 0.1 s hop
    stats = _flight(jump)
    assert stats["longest_flight_s"] == pytest.approx(0.3) and stats["flight_s"] == pytest.approx(0.4)
    lifted = jump.copy()
    lifted[..., 1] += 0.4  # a floor 40 cm up (a generated motion): same flights
    assert _flight(lifted) == stats
    handstand = stand.copy()
    handstand[:, [7, 8, 10, 11], 1] = 1.5  # feet up the whole clip: their own level is up, not flight
    assert _flight(handstand)["flight_s"] == 0.0


def test_real_shared_deepmimic_duplicates(shared_data: Path, tmp_path: Path) -> None:
    """On ../shared: the DeepMimic clips present in both folders are kept once (skips without ../shared)."""
    from simdiff.data.corpus.src_deepmimic import discover

    if not (shared_data / "extra" / "deepmimic-xbpeng.tar.xz").is_file():
        pytest.skip("no extra/deepmimic-xbpeng.tar.xz")
    items = discover(shared_data, tmp_path)
    assert len({i.meta["sha1"] for i in items}) == len(items)
    assert len({i.id for i in items}) == len(items) and len(items) >= 20
    assert "dm_backflip" in {i.id for i in items} and "dm_bridge" in {i.id for i in items}


def test_item_cache_key_follows_bytes_code_and_settings(shared: Path, tmp_path: Path) -> None:
    from dataclasses import replace

    from simdiff.data.corpus.build import code_digest, item_key
    from simdiff.data.corpus.clips import ClipSettings

    item = next(i for i in discover_all(shared, tmp_path) if i.id == "dm_jump")
    settings = ClipSettings(out=tmp_path, shared=shared)
    code = code_digest()
    key = item_key(item, settings, code)
    assert key == item_key(item, settings, code)
    assert key != item_key(item, settings, code + "x")
    assert key != item_key(item, replace(settings, seed=1), code)
    copy = tmp_path / "jump.txt"
    copy.write_text(item.path.read_text().replace("]]", ", ]]", 0) + " ")
    assert key != item_key(replace(item, path=copy), settings, code)
