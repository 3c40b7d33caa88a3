"""``--share-mirrors`` derives a mirrored clip's pairs from its original's rollouts."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from simdiff.data.augment import AugmentConfig, augment
from simdiff.data.augment.pairs import load_source_joints, rollout_to_layout
from simdiff.data.augment.share import group_mirrors, mirror_env, mirror_sources
from simdiff.errors import SimdiffError
from simdiff.eval.testing import write_tiny_corpus
from simdiff.motion.features import features_to_joints, process_joints
from simdiff.motion.mirror import mirror_caption, mirror_joints
from simdiff.sim.env import Environment


class CountingProjector:
    """Deterministic fake simulator: shifts the motion by the wind (a mirror-equivariant response)."""

    def __init__(self) -> None:
        self.motions = 0

    @staticmethod
    def response(joints: np.ndarray, env: Environment) -> np.ndarray:
        g, wx, wy = env.as_tuple()
        shift = np.array([0.002 * wx, 0.0, 0.002 * wy + 0.001 * (g + 9.81)], dtype=np.float32)
        t = np.arange(len(joints), dtype=np.float32)[:, None, None] / len(joints)
        return (np.asarray(joints, dtype=np.float32) + t * shift).astype(np.float32)

    def __call__(self, motions, envs):
        for m, e in zip(motions, envs):
            self.motions += 1
            g, wx, wy = e.as_tuple()
            yield self.response(m, e), {"success": True, "d_l2_pose": 1.0, "d_l2": 2.0, "residual": {"force_mean_mg": 0.01},
                                        "cpu_s": 0.5, "n_out": len(m), "env": [g, wx, wy]}


def _corpus_with_mirrors(root: Path, n: int) -> tuple[Path, list[str]]:
    """Tiny corpus whose train split holds ``n`` clips followed by their mirrors ``M<id>``."""
    corpus = write_tiny_corpus(root, n_train=n, n_val=0, n_test=1, frames=40)
    clips = (corpus / "train.txt").read_text(encoding="utf-8").split()
    for clip in clips:
        feats = process_joints(mirror_joints(load_source_joints(corpus, clip)).astype(np.float64)).features
        np.save(corpus / "new_joint_vecs" / f"M{clip}.npy", feats.astype(np.float32))
        np.save(corpus / "new_joints" / f"M{clip}.npy", np.asarray(features_to_joints(feats), dtype=np.float32))
        text = (corpus / "texts" / f"{clip}.txt").read_text(encoding="utf-8")
        (corpus / "texts" / f"M{clip}.txt").write_text(mirror_caption(text), encoding="utf-8")
    ids = clips + [f"M{c}" for c in clips]
    (corpus / "train.txt").write_text("".join(f"{c}\n" for c in ids), encoding="utf-8")
    return corpus, ids


def _records(out: Path) -> dict[str, dict]:
    return {r["id"]: r for p in sorted((out / "shards").glob("*.json"))
            for r in json.loads(p.read_text(encoding="utf-8"))["records"]}


def test_mirror_env_negates_the_hml_x_wind_only() -> None:
    assert mirror_env(Environment(-3.0, 4.0, -2.0)).as_tuple() == (-3.0, -4.0, -2.0)
    assert mirror_env(mirror_env(Environment(-9.81, 7.5, 1.0))) == Environment(-9.81, 7.5, 1.0)
    # the wind component along HumanML3D x is the world-y gravity component (world y = HumanML3D x)
    assert Environment(-9.81, 5.0, 0.0).gravity_vector(1.0)[1] == 5.0


def test_group_mirrors_keeps_each_mirror_beside_its_original() -> None:
    clips = ["a", "b", "Ma", "Mc", "Mb"]
    assert mirror_sources(clips) == {"Ma": "a", "Mb": "b"}
    assert group_mirrors(clips) == [["a", "Ma"], ["b", "Mb"], ["Mc"]]


def test_derived_pair_is_the_mirror_of_the_simulated_one(tmp_path: Path) -> None:
    corpus, ids = _corpus_with_mirrors(tmp_path / "corpus", 1)
    x, mx = ids
    proj = CountingProjector()
    out = tmp_path / "aug"
    report = augment(corpus, out, AugmentConfig(mode="paired", conditions=3, share_mirrors=True), projector=proj,
                     progress=False)
    assert proj.motions == 4  # X at Earth + 3 draws; MX not simulated
    recs = _records(out)
    source = load_source_joints(corpus, x)
    for k in range(4):
        rx, rm = recs[f"{x}_e{k:02d}"], recs[f"{mx}_e{k:02d}"]
        assert rm["mirrored_from"] == rx["id"] and "mirrored_from" not in rx
        assert rm["env"] == list(mirror_env(Environment(*rx["env"])).as_tuple())
        assert rm["info"]["env"] == rm["env"]
        assert (rm["written"], rm["reason"], rm["condition"], rm["factor"]) == (rx["written"], rx["reason"], k, rx["factor"])
        assert rm["written"]
        rollout = CountingProjector.response(source, Environment(*rx["env"]))
        feats, joints = rollout_to_layout(mirror_joints(rollout))
        np.testing.assert_allclose(np.load(out / "new_joint_vecs" / f"{rm['id']}.npy"), feats, atol=1e-5)
        np.testing.assert_allclose(np.load(out / "new_joints" / f"{rm['id']}.npy"), joints, atol=1e-5)
        assert (out / "texts" / f"{rm['id']}.txt").read_bytes() == (corpus / "texts" / f"{mx}.txt").read_bytes()
    env = json.loads((out / "env.json").read_text(encoding="utf-8"))
    assert env[f"{mx}_e01"]["env"] == recs[f"{mx}_e01"]["env"] and env[f"{mx}_e01"]["source"] == mx
    assert report["mirrored_pairs"] == 4 and report["kept"] == 8
    assert report["confound"]["pairs"] == 4  # only the drawn φ
    assert report["sim_cpu_s_total"] == pytest.approx(4 * 0.5)


def test_share_mirrors_halves_the_projections_and_resumes(tmp_path: Path) -> None:
    corpus, ids = _corpus_with_mirrors(tmp_path / "corpus", 3)
    full, shared = CountingProjector(), CountingProjector()
    augment(corpus, tmp_path / "full", AugmentConfig(mode="paired", conditions=2, shard_size=2), projector=full,
            progress=False)
    config = AugmentConfig(mode="paired", conditions=2, shard_size=2, share_mirrors=True)
    augment(corpus, tmp_path / "shared", config, projector=shared, progress=False)
    assert full.motions == 6 * 3 and shared.motions == full.motions // 2
    recs = _records(tmp_path / "shared")
    assert len(recs) == 18 and sum("mirrored_from" in r for r in recs.values()) == 9
    shards = sorted((tmp_path / "shared" / "shards").glob("*.json"))
    for p in shards:  # every mirror sits in its original's shard
        clips = json.loads(p.read_text(encoding="utf-8"))["clips"]
        assert all(c[1:] in clips for c in clips if c.startswith("M"))
    again = CountingProjector()
    before = {p.name: p.read_bytes() for p in shards}
    augment(corpus, tmp_path / "shared", config, projector=again, progress=False)
    assert again.motions == 0
    assert {p.name: p.read_bytes() for p in sorted((tmp_path / "shared" / "shards").glob("*.json"))} == before
    with pytest.raises(SimdiffError, match="different settings"):
        augment(corpus, tmp_path / "shared", AugmentConfig(mode="paired", conditions=2, shard_size=2),
                projector=CountingProjector(), progress=False)


def test_share_mirrors_refuses_a_shared_condition_list(tmp_path: Path) -> None:
    corpus, _ = _corpus_with_mirrors(tmp_path / "corpus", 1)
    with pytest.raises(SimdiffError, match="--share-mirrors needs paired or binary"):
        augment(corpus, tmp_path / "aug", AugmentConfig(mode="random", conditions=3, share_mirrors=True),
                projector=CountingProjector(), progress=False)
