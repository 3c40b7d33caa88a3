"""Simulator-augmented corpus: conditions, the keep filter, sharded/resumable driver, dataset."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest

from simdiff.data.augment import (AugmentConfig, AugmentedHumanML3D, FilterConfig, augment, keep_pair, make_conditions,
                                  open_training_dataset, random_conditions)
from simdiff.data.augment.pairs import load_source_joints
from simdiff.data.augment.filter import rejections, residual_newtons
from simdiff.errors import SimdiffError
from simdiff.eval.testing import write_tiny_corpus
from simdiff.sim.env import Environment
from simdiff.data.batch import collate


def fake_info(env: Environment, i: int) -> dict:
    """Deterministic outcome: g > −5 falls, w_x > 5 is unfaithful, w_y > 5 needs much residual."""
    g, wx, wy = env.as_tuple()
    return {"success": not (g != -9.81 and g > -5.0), "d_l2_pose": 10.0 if wx > 5 else 1.0 + 0.01 * i, "d_l2": 5.0,
            "residual": {"force_mean_mg": 0.3 if wy > 5 else 0.05}, "cpu_s": 0.0}


def fake_rollout(joints: np.ndarray) -> np.ndarray:
    return np.asarray(joints) + np.array([0.0, 0.0, 0.01], dtype=np.float32)


class FakeProjector:
    def __init__(self) -> None:
        self.calls = 0

    def __call__(self, motions, envs):
        self.calls += 1
        for i, (m, e) in enumerate(zip(motions, envs)):
            yield fake_rollout(m), fake_info(e, i)


def test_conditions_are_one_factor_balanced_and_seeded() -> None:
    conds = random_conditions(30, seed=3)
    assert [c.factor for c in conds[:3]] == ["gravity", "wind_x", "wind_y"]
    assert sum(c.factor == "gravity" for c in conds) == 10
    for c in conds:
        g, wx, wy = c.env.as_tuple()
        if c.factor == "gravity":
            assert -20 <= g <= -1 and wx == wy == 0
        else:
            assert g == -9.81 and (wx == 0) != (wy == 0) or (wx == wy == 0)
            assert abs(wx) <= 10 and abs(wy) <= 10
    assert random_conditions(30, seed=3) == conds and random_conditions(30, seed=4) != conds
    assert [c.env.as_tuple() for c in make_conditions("binary")] == [(-9.81, 0.0, 0.0)]
    with pytest.raises(SimdiffError, match="mode"):
        make_conditions("lunar")


def test_keep_filter_is_pure_and_ordered() -> None:
    cfg = FilterConfig(max_pose_d_l2=3.0, max_residual_n=70.0)
    ok = {"success": True, "d_l2_pose": 2.9, "d_l2": 9.0, "env": [-9.81, 0, 0], "residual": {"force_mean_n": 30.0}}
    assert keep_pair(ok, cfg) == (True, "kept")  # the paper's d_L2 is off by default
    assert keep_pair("RuntimeError: boom", cfg) == (False, "error")
    assert keep_pair(None, cfg) == (False, "error")
    assert keep_pair({**ok, "success": False, "d_l2_pose": 99}, cfg) == (False, "failed")
    assert keep_pair({**ok, "d_l2_pose": 3.01}, cfg) == (False, "faithfulness")
    assert keep_pair({**ok, "d_l2_pose": 3.0}, cfg) == (True, "kept")
    assert keep_pair({**ok, "d_l2_pose": float("nan")}, cfg) == (False, "faithfulness")
    assert keep_pair({k: v for k, v in ok.items() if k != "d_l2_pose"}, cfg) == (False, "faithfulness")
    assert keep_pair({**ok, "residual": {"force_mean_n": 70.5}}, cfg) == (False, "residual")
    assert keep_pair(ok, FilterConfig(max_pose_d_l2=3.0, max_residual_n=70.0, max_d_l2=7.0)) == (False, "faithfulness")
    assert ok["d_l2_pose"] == 2.9 and ok["residual"] == {"force_mean_n": 30.0}  # untouched


def test_residual_budget_is_absolute_in_newtons() -> None:
    """The same 40 N passes at every gravity; a budget relative to m·|g_z| would reject it on the Moon."""
    cfg = FilterConfig(max_pose_d_l2=None, max_residual_n=70.6)
    for g in (-1.6, -9.81, -20.0):
        info = {"success": True, "env": [g, 0, 0], "residual": {"force_mean_mg": 40.0 / (72.0 * abs(g))}}
        assert residual_newtons(info) == pytest.approx(40.0)
        assert keep_pair(info, cfg) == (True, "kept"), g
    moon = {"success": True, "env": [-1.6, 0, 0], "residual": {"force_mean_mg": 40.0 / (72.0 * 1.6)}}
    assert keep_pair(moon, FilterConfig(max_pose_d_l2=None, max_residual_n=None, max_residual=0.1)) == (False, "residual")


def test_rejections_judge_each_criterion_on_its_own() -> None:
    cfg = FilterConfig(max_pose_d_l2=3.0, max_residual_n=70.0)
    bad = {"success": False, "d_l2_pose": 5.0, "residual": {"force_mean_n": 100.0}}
    assert rejections(bad, cfg) == {"failed": True, "faithfulness": True, "residual": True}
    assert keep_pair(bad, cfg) == (False, "failed")  # the reason is the first, the report counts all three
    assert rejections({**bad, "success": True, "d_l2_pose": 1.0}, cfg) == {"failed": False, "faithfulness": False,
                                                                          "residual": True}
    assert all(rejections("boom", cfg).values())



def test_source_joints_have_one_more_frame(tmp_path: Path) -> None:
    corpus = write_tiny_corpus(tmp_path / "c", n_train=2, n_test=1, frames=50)
    joints = load_source_joints(corpus, "000000")
    assert joints.shape == (50, 22, 3)
    assert np.allclose(joints[:-1], np.load(corpus / "new_joints" / "000000.npy"), atol=1e-5)


def _tree(root: Path) -> dict[str, bytes]:
    skip = {"report.json", "report.md"}
    return {str(p.relative_to(root)): p.read_bytes() for p in sorted(root.rglob("*")) if p.is_file() and p.name not in skip}


def test_augment_random_writes_layout_env_and_report(tmp_path: Path) -> None:
    corpus = write_tiny_corpus(tmp_path / "c", n_train=3, n_test=2, frames=48)
    out = tmp_path / "aug"
    config = AugmentConfig(mode="random", conditions=6, seed=1, shard_size=2)
    report = augment(corpus, out, config, projector=FakeProjector(), progress=False)
    conds = make_conditions("random", 6, 1)
    expected = {f"{c:06d}_e{k.index:02d}" for c in range(3) for k in conds if keep_pair(fake_info(k.env, 0))[0]}
    ids = (out / "train.txt").read_text().split()
    assert set(ids) == expected and len(ids) == report["kept"]
    assert report["pairs"] == 18 and len(report["per_condition"]) == 6
    for row in report["per_condition"]:
        assert row["pairs"] == 3 and row["kept_fraction"] in (0.0, 1.0)
    env = json.loads((out / "env.json").read_text())
    some = ids[0]
    cond = int(some.split("_e")[1])
    assert env[some]["env"] == list(conds[cond].env.as_tuple()) and env[some]["env_index"] == cond
    assert (out / "texts" / f"{some}.txt").read_bytes() == (corpus / "texts" / f"{some.split('_e')[0]}.txt").read_bytes()
    assert np.load(out / "new_joint_vecs" / f"{some}.npy").shape == (47, 263)
    assert (out / "Mean.npy").read_bytes() == (corpus / "Mean.npy").read_bytes()
    assert sorted(p.name for p in (out / "shards").iterdir()) == ["shard_00000.json", "shard_00001.json"]
    assert "| kept %" in (out / "report.md").read_text()
    # a second run with the same settings does nothing; different settings are refused
    fake = FakeProjector()
    augment(corpus, out, config, projector=fake, progress=False)
    assert fake.calls == 0
    with pytest.raises(SimdiffError, match="different settings"):
        augment(corpus, out, AugmentConfig(mode="random", conditions=7, seed=1, shard_size=2), projector=fake, progress=False)


def test_augment_binary_and_dataset_items(tmp_path: Path) -> None:
    corpus = write_tiny_corpus(tmp_path / "c", n_train=3, n_test=1, frames=48)
    out = tmp_path / "bin"
    augment(corpus, out, AugmentConfig(mode="binary"), projector=FakeProjector(), progress=False)
    ds = AugmentedHumanML3D(out, source=corpus)
    assert len(ds) == 6
    items = [ds.get(i, np.random.default_rng(i)) for i in range(len(ds))]
    assert [it["env_index"] for it in items] == [1, 1, 1, 0, 0, 0]
    assert all(it["env"].shape == (3,) and it["env"].dtype == np.float32 for it in items)
    batch = collate(items)
    assert batch["env"].shape == (6, 3) and batch["env_index"].tolist() == [1, 1, 1, 0, 0, 0]
    assert isinstance(open_training_dataset(out), AugmentedHumanML3D)
    assert not isinstance(open_training_dataset(corpus), AugmentedHumanML3D)
    with pytest.raises(SimdiffError, match="env.json"):
        AugmentedHumanML3D(corpus)


def test_augment_refuses_test_split_and_bad_corpus(tmp_path: Path) -> None:
    corpus = write_tiny_corpus(tmp_path / "c", n_train=1, n_test=1, frames=48)
    with pytest.raises(SimdiffError, match="test split"):
        augment(corpus, tmp_path / "o", AugmentConfig(split="test"), projector=FakeProjector(), progress=False)
    with pytest.raises(SimdiffError, match="not found"):
        augment(tmp_path / "nope", tmp_path / "o", projector=FakeProjector(), progress=False)


SCRIPT = textwrap.dedent('''
    import sys, time
    import numpy as np
    sys.path.insert(0, {tests!r})
    from test_augment import fake_info, fake_rollout
    from simdiff.data.augment import AugmentConfig, augment

    calls = []

    def slow(motions, envs):
        # shard 0 runs; from shard 1 on, yield one pair, then hang (until killed) inside the shard
        calls.append(1)
        for i, (m, e) in enumerate(zip(motions, envs)):
            if len(calls) > 1 and i == 1:
                open({marker!r}, "w").close()
                time.sleep(600)
            yield fake_rollout(m), fake_info(e, i)

    augment({corpus!r}, {out!r}, AugmentConfig(mode="random", conditions=3, seed=2, shard_size=1),
            projector=slow, progress=False)
''')


def test_augment_resumes_after_kill_with_identical_output(tmp_path: Path) -> None:
    corpus = write_tiny_corpus(tmp_path / "c", n_train=4, n_test=1, frames=48)
    killed, clean = tmp_path / "killed", tmp_path / "clean"
    script = tmp_path / "run.py"
    marker = tmp_path / "inside_shard_1"
    script.write_text(SCRIPT.format(tests=str(Path(__file__).parent), corpus=str(corpus), out=str(killed),
                                    marker=str(marker)))
    env = {**os.environ, "OMP_NUM_THREADS": "1"}
    proc = subprocess.Popen([sys.executable, str(script)], env=env, stderr=subprocess.PIPE)
    first = killed / "shards" / "shard_00000.json"
    deadline = time.time() + 120
    while not marker.is_file() and time.time() < deadline and proc.poll() is None:
        time.sleep(0.02)
    proc.send_signal(signal.SIGKILL)  # inside shard 1, one of its pairs done
    proc.wait(10)
    assert first.is_file(), proc.stderr.read().decode() if proc.stderr else ""
    done = sorted(p.name for p in (killed / "shards").glob("shard_*.json"))
    assert done == ["shard_00000.json"]
    assert not (killed / "train.txt").exists()
    assert not list((killed / "shards").glob(".*tmp"))
    fake = FakeProjector()
    config = AugmentConfig(mode="random", conditions=3, seed=2, shard_size=1)
    augment(corpus, killed, config, projector=fake, progress=False)
    assert fake.calls == 3  # shards 1..3 only
    augment(corpus, clean, config, projector=FakeProjector(), progress=False)
    assert _tree(killed) == _tree(clean)


def test_cli_with_the_real_simulator(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from simdiff.cli.main import main

    corpus = write_tiny_corpus(tmp_path / "c", n_train=1, n_test=1, frames=48)
    out = tmp_path / "aug"
    code = main(["data", "augment", "--corpus", str(corpus), "--out", str(out), "--mode", "binary", "--backend", "serial",
                 "--no-progress"])
    assert code == 0 and "pairs" in capsys.readouterr().out
    report = json.loads((out / "report.json").read_text())
    assert report["pairs"] == 1 and report["per_condition"][0]["env"] == [-9.81, 0.0, 0.0]
    record = json.loads((out / "shards" / "shard_00000.json").read_text())["records"][0]
    assert isinstance(record["info"], dict) and "d_l2" in record["info"]
    assert main(["data", "augment", "--corpus", str(corpus), "--out", str(out), "--mode", "random", "--no-progress"]) == 2


def test_per_clip_assigns_balanced_round_robin_conditions(tmp_path: Path) -> None:
    from simdiff.data.augment.run import assign_conditions

    conds = make_conditions("random", 6, 0)
    clips = [f"{i:06d}" for i in range(6)]
    assigned = assign_conditions(clips, conds, 2)
    assert [k.index for k in assigned["000000"]] == [0, 1] and [k.index for k in assigned["000004"]] == [2, 3]
    counts = np.bincount([k.index for c in clips for k in assigned[c]], minlength=6)
    assert counts.tolist() == [2] * 6
    assert assign_conditions(clips, conds, None)["000003"] == list(conds)
    with pytest.raises(SimdiffError, match="per-clip"):
        assign_conditions(clips, conds, 0)
    corpus = write_tiny_corpus(tmp_path / "c", n_train=3, n_test=2, frames=48)
    out = tmp_path / "aug"
    report = augment(corpus, out, AugmentConfig(mode="random", conditions=6, seed=1, shard_size=2, per_clip=2),
                     projector=FakeProjector(), progress=False)
    assert report["pairs"] == 6 and report["settings"]["per_clip"] == 2
    seen = [(r["clip"], r["condition"]) for p in sorted((out / "shards").glob("*.json"))
            for r in json.loads(p.read_text())["records"]]
    assert seen == [("000000", 0), ("000000", 1), ("000001", 2), ("000001", 3), ("000002", 4), ("000002", 5)]


def test_training_dataset_concatenates_augmented_corpora(tmp_path: Path) -> None:
    from simdiff.data.augment.dataset import ConcatItems

    corpus = write_tiny_corpus(tmp_path / "c", n_train=3, n_test=2, frames=48)
    a, b = tmp_path / "a", tmp_path / "b"
    augment(corpus, a, AugmentConfig(mode="binary"), projector=FakeProjector(), progress=False)
    augment(corpus, b, AugmentConfig(mode="random", conditions=6, seed=1, per_clip=2), projector=FakeProjector(),
            progress=False)
    one, two = open_training_dataset(a), open_training_dataset(b)
    both = open_training_dataset([a, b])
    assert isinstance(both, ConcatItems) and len(both) == len(one) + len(two) > len(one)
    rng = np.random.default_rng(0)
    last = both.get(len(both) - 1, rng)
    assert last["env"].shape == (3,) and "caption" in last
    assert both.get(0, np.random.default_rng(0))["env"].tolist() == pytest.approx([-9.81, 0.0, 0.0])
    with pytest.raises(SimdiffError, match="out of range"):
        both.get(len(both))
