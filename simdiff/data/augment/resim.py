"""Re-simulate, in an existing run, only the pairs whose physics changed (``--resimulate-gravity-below``).

Every shard record carries ``sim_version`` (:data:`simdiff.sim.project.SIM_VERSION`; records
without it are version 1). When the simulator changes for part of φ space (version 2:
actuators and balance scale with max(1, |g_z|/9.81), so exactly the pairs with g_z < −9.81
changed and every other pair is bit-identical), a finished run need not be redone:
:func:`resimulate` re-projects, in every finished shard, the *original* pairs (not
``mirrored_from``) with g_z below the bound and an older ``sim_version``, re-derives their
mirrored pairs as ``--share-mirrors`` does (:mod:`simdiff.data.augment.share`), rewrites their
files and the shard; the run then finalises as usual (keep decision, auto threshold, report).

Crash safety, per shard: (1) the shard is rewritten with the affected records marked
:data:`PENDING` (not written, reason ``"error"``): from then on finalize never keeps them and
deletes their files; (2) the new rollouts' files are written, each atomically; (3) the shard is
rewritten with the new records. Every write is atomic (temp file + ``os.replace``), so a crash
at any point leaves a consistent folder, and running the same command again resumes (pending
records still have the old version). A clip whose source fails to load keeps its records.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from simdiff.data.augment.conditions import AugmentEnv
from simdiff.data.augment.pairs import info_dict, load_source_joints, pair_record
from simdiff.data.augment.projector import Projector
from simdiff.data.augment.share import mirror_info, mirror_rollout
from simdiff.data.writer import write_json
from simdiff.errors import SimdiffError
from simdiff.fsio import read_json
from simdiff.sim.env import Environment
from simdiff.sim.project import SIM_VERSION

PENDING = "re-simulation pending"
"""``info`` of a record whose re-simulation has started but not finished."""


def is_stale(record: dict[str, Any], gravity_below: float) -> bool:
    """True for an original pair with g_z < ``gravity_below`` simulated by an older physics version."""
    if record.get("mirrored_from"):
        return False
    env = record.get("env")
    if env is None or not float(env[0]) < gravity_below:
        return False
    return int(record.get("sim_version", 1)) < SIM_VERSION


def _condition(record: dict[str, Any]) -> AugmentEnv:
    return AugmentEnv(int(record["condition"]), str(record.get("factor", "")), Environment(*map(float, record["env"])))


def count_stale(paths: Sequence[Path], gravity_below: float) -> int:
    """Original pairs :func:`resimulate` would project in these shard files."""
    return sum(is_stale(r, gravity_below) for p in paths if p.is_file() for r in read_json(p)["records"])


def resimulate_shard(corpus: Path, out: Path, path: Path, projector: Projector, gravity_below: float,
                     tick: Callable[[int], None] = lambda n: None) -> int:
    """Re-project the stale pairs of one finished shard file (see the module docstring); returns how many."""
    shard = read_json(path)
    records: list[dict[str, Any]] = shard["records"]
    joints: dict[str, np.ndarray] = {}
    for clip in dict.fromkeys(r["clip"] for r in records if is_stale(r, gravity_below)):
        try:
            joints[clip] = load_source_joints(corpus, clip)
        except SimdiffError:
            continue  # the source fails to load: its records stay as they are
    targets = [r for r in records if is_stale(r, gravity_below) and r["clip"] in joints]
    if not targets:
        return 0
    ids = {r["id"] for r in targets}
    derived = [r for r in records if r.get("mirrored_from") in ids]
    touched = ids | {r["id"] for r in derived}
    pending = [{**r, "written": False, "reason": "error", "info": PENDING, "signal": None} if r["id"] in touched else r
               for r in records]
    write_json(path, {**shard, "records": pending})  # (1)
    results = iter(projector([joints[r["clip"]] for r in targets], [_condition(r).env for r in targets]))
    new: dict[str, dict[str, Any]] = {}
    simulated: dict[str, tuple[Any, Any]] = {}
    for r in targets:  # (2)
        try:
            rollout, info = next(results)
        except StopIteration:
            raise SimdiffError(f"the projector returned fewer results than the {len(targets)} motions given") from None
        simulated[r["id"]] = (rollout, info_dict(info))
        new[r["id"]] = pair_record(corpus, out, r["clip"], _condition(r), rollout, info_dict(info), r.get("content"))
        tick(1)
    for r in derived:
        rollout, info = simulated[r["mirrored_from"]]
        cond = _condition(r)
        record = pair_record(corpus, out, r["clip"], cond, mirror_rollout(rollout), mirror_info(info, cond.env),
                              r.get("content"))
        new[r["id"]] = {**record, "mirrored_from": r["mirrored_from"]}
    write_json(path, {**shard, "records": [new.get(r["id"], r) for r in records]})  # (3)
    return len(targets)


def resimulate(corpus: Path, out: Path, paths: Sequence[Path], projector: Projector, gravity_below: float,
               progress: bool = True) -> int:
    """Re-project the stale pairs of every existing shard in ``paths``; returns the number projected.

    Args:
        corpus: the run's source corpus; out: the run folder.
        paths: shard files of the run (missing ones are skipped).
        projector: the run's projector (the current simulator).
        gravity_below: re-simulate pairs with g_z strictly below this (m/s²); −9.81 selects
            exactly the pairs that version 2 changed.
        progress: a tqdm bar on stderr.
    """
    from tqdm import tqdm

    if not np.isfinite(gravity_below):
        raise SimdiffError(f"--resimulate-gravity-below must be a finite gravity (m/s²), got {gravity_below}")
    total = count_stale(paths, gravity_below)
    done = 0
    with tqdm(total=total, desc="re-simulate", unit="pair", disable=not progress or total == 0,
              dynamic_ncols=True) as bar:
        for path in paths:
            if path.is_file():
                done += resimulate_shard(corpus, out, path, projector, gravity_below, bar.update)
    return done
