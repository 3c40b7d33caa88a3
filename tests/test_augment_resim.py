"""``--resimulate-gravity-below`` re-projects only the pairs whose physics changed, resumably."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from test_augment_mirrors import CountingProjector, _corpus_with_mirrors

from simdiff.cli.main import main
from simdiff.data.augment import AugmentConfig, augment
from simdiff.data.augment.resim import PENDING, is_stale
from simdiff.errors import SimdiffError
from simdiff.sim.env import Environment
from simdiff.sim.project import SIM_VERSION

BOUND = -9.81
# seed 4 draws, per clip 000000 / 000001 / 000002: g = (-14.05, -19.22), (-19.67, -4.05), (-10.77, -3.01)
CONFIG = dict(mode="paired", conditions=6, seed=4, shard_size=1, share_mirrors=True)


class Versioned(CountingProjector):
    """Fake simulator in two versions; ``new_below``: version 2 only for g_z below it (the others unchanged)."""

    def __init__(self, new_below: float | None = None, crash_after: int | None = None) -> None:
        super().__init__()
        self.new_below, self.crash_after, self.envs = new_below, crash_after, []

    def __call__(self, motions, envs):
        for m, e in zip(motions, envs):
            if self.crash_after is not None and self.motions >= self.crash_after:
                raise KeyboardInterrupt("killed")
            self.motions += 1
            self.envs.append(e.as_tuple())
            new = self.new_below is not None and e.gravity < self.new_below
            out = self.response(m, e)
            if new:  # version 2 raises the left wrist by 5 cm
                out = out.copy()
                out[:, 20, 1] += 0.05
            yield out, {"success": True, "d_l2_pose": 3.0 if new else 1.0, "residual": {"force_mean_n": 5.0},
                        "cpu_s": 0.5, "n_out": len(m), "env": list(e.as_tuple())}


def _strip_versions(out: Path) -> None:
    """Make ``out`` look like a run of the previous simulator (records without ``sim_version``)."""
    for path in (out / "shards").glob("*.json"):
        shard = json.loads(path.read_text(encoding="utf-8"))
        for r in shard["records"]:
            r.pop("sim_version", None)
        path.write_text(json.dumps(shard), encoding="utf-8")


def _files(out: Path) -> dict[str, bytes]:
    return {str(p.relative_to(out)): p.read_bytes() for sub in ("new_joint_vecs", "new_joints", "texts")
            for p in sorted((out / sub).glob("*"))}


def _records(out: Path, versions: bool = False) -> list[dict]:
    """Shard records, ``sim_version`` dropped from the pairs not re-simulated (|g_z| ≤ 9.81) unless ``versions``."""
    recs = [r for p in sorted((out / "shards").glob("*.json")) for r in json.loads(p.read_text(encoding="utf-8"))["records"]]
    return recs if versions else [r if r["env"][0] < BOUND else {k: v for k, v in r.items() if k != "sim_version"}
                                  for r in recs]


@pytest.fixture()
def old_run(tmp_path: Path) -> tuple[Path, Path, Path]:
    """A finished run of version 1 and a fresh run where version 2 made exactly the g_z < −9.81 pairs."""
    corpus, _ = _corpus_with_mirrors(tmp_path / "corpus", 3)
    out = tmp_path / "old"
    augment(corpus, out, AugmentConfig(**CONFIG), projector=Versioned(), progress=False)
    _strip_versions(out)
    expected = tmp_path / "expected"
    augment(corpus, expected, AugmentConfig(**CONFIG), projector=Versioned(new_below=BOUND), progress=False)
    return corpus, out, expected


def test_stale_means_an_original_pair_below_the_bound_of_an_older_version() -> None:
    rec = {"id": "a_e01", "env": [-12.0, 0.0, 0.0]}
    assert is_stale(rec, BOUND) and is_stale({**rec, "sim_version": 1}, BOUND)
    assert not is_stale({**rec, "sim_version": SIM_VERSION}, BOUND)
    assert not is_stale({**rec, "mirrored_from": "b_e01"}, BOUND)  # re-derived with its original
    assert not is_stale({**rec, "env": [-9.81, 5.0, 0.0]}, BOUND)  # Earth gravity (and wind): unchanged


def test_resimulates_only_the_changed_pairs_and_equals_a_fresh_run(old_run: tuple[Path, Path, Path]) -> None:
    corpus, out, expected = old_run
    before = _files(out)
    v2 = Versioned(new_below=BOUND)
    report = augment(corpus, out, AugmentConfig(**CONFIG, resimulate_gravity_below=BOUND), projector=v2, progress=False)
    assert [round(g, 2) for g in sorted(g for g, _, _ in v2.envs)] == [-19.67, -19.22, -14.05, -10.77]  # 4 originals
    assert _records(out) == _records(expected)  # mirrors re-derived, versions set, the rest untouched
    assert all(("sim_version" in r) == (r["env"][0] < BOUND) for r in _records(out, versions=True))
    after = _files(out)
    assert after == _files(expected)
    changed = {k for k in after if before.get(k) != after[k]}
    stale_ids = {r["id"] for r in _records(expected) if r["env"][0] < BOUND}
    assert len(stale_ids) == 8 and {Path(k).stem for k in changed} == stale_ids  # 4 originals + their mirrors
    assert report == json.loads((expected / "report.json").read_text(encoding="utf-8")) | {"wall_s_this_run": report["wall_s_this_run"]}
    for name in ("train.txt", "env.json"):
        assert (out / name).read_bytes() == (expected / name).read_bytes()
    again = Versioned(new_below=BOUND)  # nothing is stale any more: the same command only re-finalises
    augment(corpus, out, AugmentConfig(**CONFIG, resimulate_gravity_below=BOUND), projector=again, progress=False)
    assert again.motions == 0 and _files(out) == after


def test_a_crash_leaves_a_consistent_folder_and_the_same_command_resumes(old_run: tuple[Path, Path, Path]) -> None:
    corpus, out, expected = old_run
    cfg = AugmentConfig(**CONFIG, resimulate_gravity_below=BOUND)
    with pytest.raises(KeyboardInterrupt):  # killed after the first shard's first pair wrote its files
        augment(corpus, out, cfg, projector=Versioned(new_below=BOUND, crash_after=1), progress=False)
    pending = [r for r in _records(out) if r["info"] == PENDING]
    assert len(pending) == 4 and all(not r["written"] and r["reason"] == "error" for r in pending)
    # finalising now (a plain run, nothing to simulate) keeps no pending pair and drops their files
    report = augment(corpus, out, AugmentConfig(**CONFIG), projector=Versioned(), progress=False)
    kept = set((out / "train.txt").read_text(encoding="utf-8").split())
    assert report["kept"] == len(kept) and not kept & {r["id"] for r in pending}
    assert not any((out / "new_joint_vecs" / f"{r['id']}.npy").exists() for r in pending)
    assert all((out / "new_joint_vecs" / f"{i}.npy").is_file() for i in kept)
    with pytest.raises(KeyboardInterrupt):  # killed again, now after the first shard was committed
        augment(corpus, out, cfg, projector=Versioned(new_below=BOUND, crash_after=2), progress=False)
    resumed = Versioned(new_below=BOUND)
    augment(corpus, out, cfg, projector=resumed, progress=False)
    assert resumed.motions == 4 - 2  # only the pairs of the shards not committed before the crash
    assert _records(out) == _records(expected) and _files(out) == _files(expected)


def test_cli_flag_and_bad_bound(tmp_path: Path, old_run: tuple[Path, Path, Path],
                                monkeypatch: pytest.MonkeyPatch) -> None:
    corpus, out, _ = old_run
    seen = {}

    def fake_augment(corpus, out, config, progress=True):
        seen["bound"] = config.resimulate_gravity_below
        return {"kept_fraction": None, "filter": {}, "kept": 0, "pairs": 0, "clips": 0}

    monkeypatch.setattr("simdiff.data.augment.run.augment", fake_augment)
    assert main(["data", "augment", "--corpus", str(corpus), "--out", str(out), "--seed", "4", "--share-mirrors",
                 "--resimulate-gravity-below", "-9.81", "--no-progress"]) == 0
    assert seen["bound"] == -9.81
    monkeypatch.undo()
    with pytest.raises(SimdiffError, match="finite"):
        augment(corpus, out, AugmentConfig(**CONFIG, resimulate_gravity_below=float("nan")), projector=Versioned(),
                progress=False)
    assert Environment(-10.0).gravity < BOUND
