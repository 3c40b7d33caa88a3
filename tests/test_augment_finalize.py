"""The keep decision at finalize (re-finalize without simulating) and the auto pose threshold."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import pytest

from test_augment import FakeProjector
from test_augment_mirrors import CountingProjector, _corpus_with_mirrors

from simdiff.cli.commands.augment import _pose_bound
from simdiff.data.augment import AugmentConfig, FilterConfig, augment, keep_pair
from simdiff.data.augment.decide import calibrate_pose_threshold, decide
from simdiff.errors import SimdiffError
from simdiff.eval.testing import write_tiny_corpus

EARTH = [-9.81, 0.0, 0.0]


def _ids(out: Path) -> list[str]:
    return (out / "train.txt").read_text(encoding="utf-8").split()


def _shard_records(out: Path) -> dict[str, dict]:
    return {r["id"]: r for p in sorted((out / "shards").glob("*.json"))
            for r in json.loads(p.read_text(encoding="utf-8"))["records"]}


def test_tracked_but_rejected_pairs_have_files_and_refinalize_without_simulating(tmp_path: Path) -> None:
    corpus = write_tiny_corpus(tmp_path / "c", n_train=3, n_test=1, frames=48)
    out = tmp_path / "aug"
    strict = AugmentConfig(mode="random", conditions=8, seed=1, shard_size=2, filter=FilterConfig(max_pose_d_l2=5.2))
    first = FakeProjector()
    augment(corpus, out, strict, projector=first, progress=False)
    assert first.calls == 2
    recs = _shard_records(out)
    tracked = {i for i, r in recs.items() if r["info"]["success"]}
    unfaithful = {i for i in tracked if r_pose(recs[i]) > 5.2}
    assert unfaithful and tracked - unfaithful and set(recs) - tracked  # every case occurs
    ids = set(_ids(out))
    assert ids == {i for i, r in recs.items() if keep_pair(r["info"], strict.filter)[0]}
    assert not ids & unfaithful
    for i in recs:  # files for every tracked pair (kept or not), none for fallen ones
        for sub, ext in (("new_joint_vecs", "npy"), ("new_joints", "npy"), ("texts", "txt")):
            assert (out / sub / f"{i}.{ext}").is_file() == (i in tracked), (i, sub)
    # only the threshold changes: the same command re-finalises, projecting nothing
    loose = AugmentConfig(mode="random", conditions=8, seed=1, shard_size=2, filter=FilterConfig(max_pose_d_l2=11.0))
    again = FakeProjector()
    report = augment(corpus, out, loose, projector=again, progress=False)
    assert again.calls == 0
    assert set(_ids(out)) == ids | unfaithful and report["kept"] == len(ids | unfaithful)
    assert report["filter"]["thresholds"]["max_pose_d_l2"] == 11.0
    assert set(json.loads((out / "env.json").read_text(encoding="utf-8"))) == ids | unfaithful
    # back to the strict filter: the rejected files stay on disk, the split shrinks again
    augment(corpus, out, strict, projector=again, progress=False)
    assert again.calls == 0 and set(_ids(out)) == ids
    assert all((out / "new_joint_vecs" / f"{i}.npy").is_file() for i in unfaithful)
    # anything but the filter still has to match
    with pytest.raises(SimdiffError, match="different settings"):
        augment(corpus, out, AugmentConfig(mode="random", conditions=8, seed=2, shard_size=2), projector=again,
                progress=False)


def r_pose(record: dict) -> float:
    return float(record["info"]["d_l2_pose"])


def _record(i: int, pose: float, env: list[float] = EARTH, success: bool = True, residual_n: float = 10.0) -> dict:
    return {"id": f"c{i}", "clip": f"c{i}", "condition": 0, "env": env, "written": success, "reason": None,
            "info": {"success": success, "d_l2_pose": pose, "residual": {"force_mean_n": residual_n}}}


def _synthetic() -> list[dict]:
    earth = [_record(i, float(i)) for i in range(1, 9)]  # 8 good Earth pairs, pose 1..8
    earth += [_record(9, 0.5, success=False), _record(10, 0.2, residual_n=500.0)]  # a fall, a residual reject
    others = [_record(20 + i, 0.1, env=[-3.0, 0.0, 0.0]) for i in range(5)]  # not Earth: ignored
    return earth + others


def test_auto_threshold_is_the_smallest_reaching_the_earth_target() -> None:
    records = _synthetic()
    out, summary = decide(records, FilterConfig(max_pose_d_l2="auto", earth_keep=0.66))
    cal = summary["calibration"]
    # 10 Earth pairs, target 0.66 -> 7 kept; the 7th smallest good pose is 7.0
    assert cal["max_pose_d_l2"] == 7.0 and cal["reachable"] and cal["earth_pairs"] == 10
    assert cal["earth_kept"] == 7 and cal["earth_keep_achieved"] == pytest.approx(0.7)
    assert summary["thresholds"]["max_pose_d_l2"] == 7.0
    kept = {r["id"] for r in out if r["kept"]}
    assert kept == {f"c{i}" for i in range(1, 8)} | {f"c{20 + i}" for i in range(5)}
    below, _ = decide(records, FilterConfig(max_pose_d_l2=6.99))  # any smaller bound misses the target
    assert sum(r["kept"] for r in below if r["env"] == EARTH) / 10 < 0.66
    reasons = {r["id"]: r["reason"] for r in out}
    assert (reasons["c8"], reasons["c9"], reasons["c10"]) == ("faithfulness", "failed", "residual")


def test_auto_threshold_when_the_target_is_unreachable() -> None:
    _, summary = decide(_synthetic(), FilterConfig(max_pose_d_l2="auto", earth_keep=0.9))
    cal = summary["calibration"]
    # 9 of 10 needed, only 8 tracked with an acceptable residual: all of them, bound = their largest pose
    assert not cal["reachable"] and cal["max_pose_d_l2"] == 8.0
    assert cal["earth_kept"] == 8 and cal["earth_keep_achieved"] == pytest.approx(0.8)


def test_auto_needs_earth_pairs_and_a_valid_target(tmp_path: Path) -> None:
    with pytest.raises(SimdiffError, match="Earth pairs"):
        calibrate_pose_threshold([_record(1, 1.0, env=[-3.0, 0.0, 0.0])], FilterConfig(max_pose_d_l2="auto"))
    with pytest.raises(SimdiffError, match="earth-keep"):
        calibrate_pose_threshold(_synthetic(), FilterConfig(max_pose_d_l2="auto", earth_keep=1.5))
    with pytest.raises(SimdiffError, match="calibrated first"):
        keep_pair(_record(1, 1.0)["info"], FilterConfig(max_pose_d_l2="auto"))
    corpus = write_tiny_corpus(tmp_path / "c", n_train=1, n_test=1, frames=48)
    fake = FakeProjector()
    with pytest.raises(SimdiffError, match="auto calibrates on Earth pairs"):  # refused before simulating
        augment(corpus, tmp_path / "aug", AugmentConfig(mode="random", conditions=3,
                                                        filter=FilterConfig(max_pose_d_l2="auto")),
                projector=fake, progress=False)
    assert fake.calls == 0
    assert _pose_bound("auto") == "auto" and _pose_bound("4.5") == 4.5
    with pytest.raises(argparse.ArgumentTypeError, match="'five'"):
        _pose_bound("five")


class PoseByWindProjector(CountingProjector):
    """CountingProjector whose pose d_L2 grows with the wind (mirror-invariant) and with each motion projected.

    Clip k's Earth pair is motion 4k + 1: pose d_L2 1.1, 1.5, 1.9 for k = 0, 1, 2.
    """

    def __call__(self, motions, envs):
        for (rollout, info), e in zip(super().__call__(motions, envs), envs):
            _, wx, wy = e.as_tuple()
            yield rollout, {**info, "d_l2_pose": 1.0 + 0.1 * self.motions + abs(wx) + abs(wy)}


def test_share_mirrors_follow_their_original_under_refinalize_and_auto(tmp_path: Path) -> None:
    corpus, clips = _corpus_with_mirrors(tmp_path / "corpus", 3)
    out = tmp_path / "aug"
    proj = PoseByWindProjector()
    strict = AugmentConfig(mode="paired", conditions=3, shard_size=2, share_mirrors=True,
                           filter=FilterConfig(max_pose_d_l2=4.0))
    augment(corpus, out, strict, projector=proj, progress=False)
    recs = _shard_records(out)
    assert proj.motions == 3 * 4 and all(r["written"] for r in recs.values())

    def consistent() -> set[str]:
        ids = set(_ids(out))
        for i, r in recs.items():
            if r.get("mirrored_from"):
                assert (i in ids) == (r["mirrored_from"] in ids), i
        return ids

    strict_ids = consistent()
    assert 0 < len(strict_ids) < len(recs)
    report = augment(corpus, out, AugmentConfig(mode="paired", conditions=3, shard_size=2, share_mirrors=True,
                                                filter=FilterConfig(max_pose_d_l2="auto", earth_keep=0.5)),
                     projector=proj, progress=False)
    assert proj.motions == 3 * 4  # re-finalised only
    cal = report["filter"]["calibration"]
    assert cal["earth_pairs"] == 3 and cal["earth_kept"] == 2 and cal["max_pose_d_l2"] == pytest.approx(1.5)
    auto_ids = consistent()
    assert auto_ids != strict_ids and "calibrated on this run's Earth pairs" in (out / "report.md").read_text()


def test_older_run_refinalizes_and_never_keeps_a_pair_without_files(tmp_path: Path) -> None:
    corpus = write_tiny_corpus(tmp_path / "c", n_train=2, n_test=1, frames=48)
    out = tmp_path / "aug"
    config = AugmentConfig(mode="random", conditions=8, seed=1, shard_size=2, filter=FilterConfig(max_pose_d_l2=5.2))
    augment(corpus, out, config, projector=FakeProjector(), progress=False)
    # make it look like an older run: filter in the settings, "kept" instead of "written", only kept pairs' files
    settings = json.loads((out / "augment_settings.json").read_text(encoding="utf-8"))
    (out / "augment_settings.json").write_text(json.dumps({**settings, "filter": {"max_pose_d_l2": 5.2}}))
    kept = set(_ids(out))
    for p in (out / "shards").glob("*.json"):
        shard = json.loads(p.read_text(encoding="utf-8"))
        for r in shard["records"]:
            r.pop("written")
            r["kept"] = r["id"] in kept
        p.write_text(json.dumps(shard), encoding="utf-8")
    loose = AugmentConfig(mode="random", conditions=8, seed=1, shard_size=2, filter=FilterConfig(max_pose_d_l2=11.0))
    again = FakeProjector()
    augment(corpus, out, loose, projector=again, progress=False)
    assert again.calls == 0 and set(_ids(out)) == kept
    assert all((out / "new_joint_vecs" / f"{i}.npy").is_file() for i in kept)


def test_residual_budget_follows_body_strength_only_above_earth_gravity() -> None:
    def info(g: float, newtons: float) -> dict:
        return {"success": True, "d_l2_pose": 1.0, "env": [g, 0.0, 0.0], "residual": {"force_mean_n": newtons}}

    config = FilterConfig(max_pose_d_l2=5.0, max_residual_n=70.0)
    assert keep_pair(info(-9.81, 69.0), config) == (True, "kept")
    assert keep_pair(info(-9.81, 71.0), config) == (False, "residual")
    assert keep_pair(info(-1.6, 71.0), config) == (False, "residual")  # absolute on the Moon, not 0.16 of it
    assert keep_pair(info(-19.62, 139.0), config) == (True, "kept")  # s = 2: 140 N
    assert keep_pair(info(-19.62, 141.0), config) == (False, "residual")
    fixed = FilterConfig(max_pose_d_l2=5.0, max_residual_n=70.0, residual_follows_strength=False)
    assert keep_pair(info(-19.62, 71.0), fixed) == (False, "residual")


class RetimingProjector(FakeProjector):
    """FakeProjector whose rollouts under w_x > 0 report a retime second try (slow-down 1.4; any rule will do)."""

    def __call__(self, motions, envs):
        for (rollout, info), e in zip(super().__call__(motions, envs), envs):
            if e.as_tuple()[1] > 0:
                info = {**info, "retime_scale": 1.4}
            yield rollout, info


def test_retimed_pairs_are_marked_in_env_json_and_left_out_of_first_try(tmp_path: Path) -> None:
    corpus = write_tiny_corpus(tmp_path / "c", n_train=3, n_test=1, frames=48)
    out = tmp_path / "aug"
    augment(corpus, out, AugmentConfig(mode="random", conditions=8, seed=1, shard_size=2,
                                       filter=FilterConfig(max_pose_d_l2=11.0)), projector=RetimingProjector(),
            progress=False)
    env = json.loads((out / "env.json").read_text(encoding="utf-8"))
    retimed = {i for i, row in env.items() if row["env"][1] > 0}
    assert retimed and set(env) - retimed  # both kinds kept
    assert all(env[i]["retime_scale"] == pytest.approx(1.4) for i in retimed)
    assert not any("retime_scale" in env[i] for i in set(env) - retimed)
    first_try = (out / "first_try.txt").read_text(encoding="utf-8").split()
    assert set(first_try) == set(env) - retimed and set(_ids(out)) == set(env)
