"""Training packs (:mod:`simdiff.data.pack`): a corpus written by the builder's own clip code round-trips.

The corpus here is made with :func:`simdiff.data.clip_files.clip_variants` (what ``simdiff data
build`` uses per window, mirrors included) from synthetic motions on a body with other and
left/right-unequal bone lengths, so the mirrors' root scale differs from 1.
"""

from __future__ import annotations

import json
import lzma
import shutil
from pathlib import Path

import numpy as np
import pytest

from simdiff.cli.main import main
from simdiff.data import pack_joints as codec
from simdiff.data.clip_files import clip_variants, write_clip, write_splits, write_stats
from simdiff.data.corpus.cmu_captions import caption_line
from simdiff.data.pack import pack, unpack
from simdiff.errors import SimdiffError
from simdiff.motion.features import features_to_joints, process_joints
from simdiff.motion.kinematics import forward_kinematics, inverse_kinematics
from simdiff.motion.skeleton import CANONICAL_OFFSETS, LEFT_CHAIN
from simdiff.motion.synthetic import jump, walk

pytestmark = pytest.mark.usefixtures("one_torch_thread")

FEATURE_TOL = 0.05
"""Largest rebuilt-feature error allowed, in units of Std (measured on the all-source corpus: 0.02)."""


def _odd_body(joints: np.ndarray) -> np.ndarray:
    """The motion on a 10 % larger body whose left leg is 8 % longer than its right."""
    offsets = CANONICAL_OFFSETS * 1.1
    left_leg = [j for j in LEFT_CHAIN if j in (1, 4, 7, 10)]
    offsets[left_leg] *= 1.08
    quats = inverse_kinematics(joints.astype(np.float64), smooth_forward=False, hip_quirk=True)
    return forward_kinematics(quats, joints[:, 0] * 1.1, offsets).astype(np.float32)


def write_builder_corpus(root: Path) -> Path:
    """Six windows (walks, a turning walk, a jump) and their mirrors, as the corpus builder writes them."""
    motions = [walk(61, speed=1.3), walk(50, speed=0.8, turn_rate=0.8, phase=1.0), jump(45, height=0.35, start=15),
               walk(70, speed=1.6, turn_rate=-0.6, phase=2.0), jump(40, height=0.2, start=12), walk(41, speed=0.5)]
    captions = ["a person walks forward", "a person turns left while walking", "a person jumps up",
                "a person walks fast turning right", "a person hops", "a person steps to the left slowly"]
    records = []
    for i, (motion, text) in enumerate(zip(motions, captions)):
        base = {"trial": f"t:{i}", "source": "synthetic", "licence": "MIT"}
        lines = [text, text + " again"]
        recs, pending = clip_variants(base, f"s{i:02d}_00", _odd_body(motion), lines, True, caption_line)
        records += recs
        for cid, features, recovered, lines in pending:
            write_clip(root, cid, features, recovered, lines)
    ids = write_splits(root, records, {f"t:{i}": ("train" if i < 4 else "test") for i in range(6)})
    write_stats(root, ids["train"])
    (root / "manifest.json").write_text(json.dumps({"clips": records}), encoding="utf-8")
    return root


@pytest.fixture(scope="module")
def built(tmp_path_factory) -> Path:
    return write_builder_corpus(tmp_path_factory.mktemp("built"))


def _feats(folder: Path, clip: str) -> np.ndarray:
    return np.load(folder / "new_joint_vecs" / f"{clip}.npy")


def test_joints_pack_round_trip_rebuilds_features_and_mirrors(built, tmp_path) -> None:
    info = pack(built, tmp_path / "pack")
    header = json.loads((tmp_path / "pack" / "pack.json").read_text())
    assert header["version"] == 2 and info["content"] == "joints"
    assert info["clips"] == 12 and info["mirrors"] == 6 and info["raw"] == 0
    assert max(info["max_rebuild_error"].values()) < FEATURE_TOL
    assert unpack(tmp_path / "pack", tmp_path / "back", workers=2) == 12
    back = tmp_path / "back"
    std = np.load(built / "Std.npy")
    index = json.loads(lzma.decompress((tmp_path / "pack" / "index.json.xz").read_bytes()))
    scales = [m[2] for m in index["mirrors"]]
    assert max(abs(s - 1.0) for s in scales) > 0.01  # the odd body makes the mirrors' root scale matter
    for path in sorted((built / "new_joint_vecs").glob("*.npy")):
        clip = path.stem
        src, got = np.load(path), _feats(back, clip)
        assert got.dtype == np.float32 and got.shape == src.shape
        err = np.abs(got - src) / std
        assert err[:, :259].max() < FEATURE_TOL, (clip, float(err.max()))
        assert np.array_equal(got[:, 259:], src[:, 259:])  # contacts stored, exact
        joints = np.load(back / "new_joints" / f"{clip}.npy")
        assert np.array_equal(joints, features_to_joints(got))
        assert np.abs(joints - np.load(built / "new_joints" / f"{clip}.npy")).max() < 0.005  # metres
        assert (back / "texts" / f"{clip}.txt").read_bytes() == (built / "texts" / f"{clip}.txt").read_bytes()
    for name in ("Mean.npy", "Std.npy"):
        assert (back / name).read_bytes() == (built / name).read_bytes()
    for split in built.glob("*.txt"):
        assert (back / split.name).read_text() == split.read_text()
    assert (back / "manifest.json").read_text() == (built / "manifest.json").read_text()


def test_mirror_root_scale_is_needed(built) -> None:
    """Without the fitted scale the rebuilt mirror is off; with it, within tolerance."""
    f, fm = _feats(built, "s00_00"), _feats(built, "Ms00_00")
    std = np.load(built / "Std.npy")
    joints = codec.canonical_joints(f)
    scale, error = codec.mirror_scale(joints, fm, std)
    assert error < FEATURE_TOL
    plain = np.abs(codec.rebuild_mirror(joints, 1.0) - fm)[:, :259] / std[:259]
    assert plain.max() > 5 * FEATURE_TOL


def test_clip_named_like_a_mirror_but_not_one_is_kept_whole(built, tmp_path) -> None:
    odd = tmp_path / "odd"
    shutil.copytree(built, odd)
    for sub in ("new_joint_vecs", "new_joints"):  # M s00 now holds another motion
        shutil.copyfile(odd / sub / "s03_00.npy", odd / sub / "Ms00_00.npy")
    info = pack(odd, tmp_path / "pack")
    assert info["clips"] == 12 and info["mirrors"] == 5 and info["raw"] == 0  # Ms00_00 stored as its own joints
    unpack(tmp_path / "pack", tmp_path / "back", workers=1)
    err = np.abs(_feats(tmp_path / "back", "Ms00_00") - _feats(odd, "Ms00_00")) / np.load(odd / "Std.npy")
    assert err.max() < FEATURE_TOL


def test_over_budget_is_one_line_naming_the_size(built, tmp_path, capsys) -> None:
    with pytest.raises(SimdiffError, match=r"pack is \d+\.\d MiB, over the 0\.001 MiB budget"):
        pack(built, tmp_path / "p", budget_mib=0.001)
    assert not (tmp_path / "p").exists() and not list(tmp_path.glob(".p.tmp*"))
    assert main(["train", "pack", str(built), "--out", str(tmp_path / "p"), "--budget-mib", "0.001",
                 "--no-progress"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "MiB, over the 0.001 MiB budget" in err[0]


def test_damaged_index_is_refused(built, tmp_path) -> None:
    pack(built, tmp_path / "pack")
    blob = (tmp_path / "pack" / "index.json.xz").read_bytes()
    (tmp_path / "pack" / "index.json.xz").write_bytes(blob[:-8])
    with pytest.raises(SimdiffError, match="does not match pack.json"):
        unpack(tmp_path / "pack", tmp_path / "back")


def test_codec_quantisation_and_deltas() -> None:
    rng = np.random.default_rng(0)
    joints = rng.uniform(-0.9, 0.9, (30, 22, 3)) + np.array([5.0, 0.9, -7.0])
    joints[:, 0] = rng.uniform(-0.05, 0.05, (30, 3)) + np.array([5.0, 0.9, -7.0])
    root, rel = codec.quantize(joints)
    back = codec.dequantize(root, rel)
    assert np.abs(back[:, 1:] - joints[:, 1:]).max() <= codec.REL_STEP / 2 + 1e-6  # float32 root rounding
    codes = rng.integers(-32768, 32767, (50, 21, 3)).astype(np.int16)  # wraps in the deltas
    assert np.array_equal(codec.delta_decode(codec.delta_encode(codes)), codes)
    joints[3, 5] += 3.0
    with pytest.raises(SimdiffError, match="from the root"):
        codec.quantize(joints, "far")


def test_rebuilt_original_matches_process_joints(built) -> None:
    """Features from the stored joints are the builder's processing of the same canonical joints."""
    f = _feats(built, "s01_00")
    joints = codec.canonical_joints(f)
    again = process_joints(joints, uniform_skeleton=False, canonical=False).features
    assert np.abs(codec.rebuild_features(joints) - again).max() == 0.0
    assert np.abs(again - f).max() < 1e-4
