"""The augmentation driver: replay every training clip under each condition, filter, write a corpus.

Output (``out``), in the HumanML3D layout plus φ::

    new_joint_vecs/<id>.npy   (T-1, 263) features of the rollout (process_joints: canonical
                              skeleton, floor, facing +Z), as the source corpus was built
    new_joints/<id>.npy       (T-1, 22, 3) the joints those features give back
    texts/<id>.txt            the source clip's caption file, copied byte for byte
    Mean.npy, Std.npy         copied from the source corpus (the model's normaliser)
    train.txt, all.txt        kept ids (``<clip>_e<condition:02d>``)
                              (features/joints/texts exist for every tracked pair, kept or not)
    first_try.txt             the kept ids whose rollout tracked the source as given (no retime second try:
                              a re-timed pair keeps its Earth apex by construction)
    env.json                  {id: {env: [g_z, w_x, w_y], env_index, condition, factor, source
                              [, retime_scale: the source's slow-down, only when re-timed]}}
    conditions.json           the condition list
    report.json, report.md    kept fraction per condition, reasons, CPU time
    augment_settings.json     what a resumed run must match
    source_corpus.json        the source corpus's path and a licence summary of the clips behind
                              the kept pairs (:mod:`simdiff.model.provenance`)
    shards/shard_NNNNN.json   one per group of ``shard_size`` source clips: every pair's projection
                              info and whether its files were written; written last (temp +
                              os.replace), so a shard either exists whole or is redone

The keep decision is made when the run finalises (:func:`simdiff.data.augment.decide.decide`,
from the shard records and ``config.filter``), not per shard: the settings a resumed run must
match leave out the filter thresholds, so re-running the same command with other thresholds
(or ``--max-pose-d-l2 auto``) re-finalises without simulating.

``env_index``: binary mode labels simulated clips 1 (0 is left for the source, kinematic
clips, see :class:`simdiff.data.augment.dataset.AugmentedHumanML3D`); random mode uses the
condition index. ``--share-mirrors`` (:mod:`simdiff.data.augment.share`): a mirrored clip
``M<id>`` whose original is in the split is not simulated; its pairs are the mirrors of
``<id>``'s under mirror(φ) (records carry ``mirrored_from``). Every record carries the
``sim_version`` of the physics that made it; ``--resimulate-gravity-below G`` re-projects, in a
finished run, the pairs with g_z < G of an older version (:mod:`simdiff.data.augment.resim`). Resuming: shards whose file exists with the same clips are skipped; files a
killed shard left behind are overwritten by its re-run, and files of no finished shard are
deleted when the run finalises.
"""

from __future__ import annotations

import json
import os
import time
from collections.abc import Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any, Callable

from simdiff.fsio import read_json as _read_json, write_text
from simdiff.data.augment.classes import load_motion_types
from simdiff.data.augment.conditions import (DEFAULT_PAIRED_K, FACTORS, AugmentEnv, check_factors, check_gravity_range,
                                             check_one_gravity, make_conditions, paired_conditions)
from simdiff.data.augment.decide import decide
from simdiff.data.augment.filter import AUTO, FilterConfig
from simdiff.data.augment.report import build_report, report_markdown
from simdiff.data.augment.share import group_mirrors, mirror_condition, mirror_info, mirror_rollout, mirror_sources
from simdiff.data.augment.pairs import clip_id_for, info_dict, load_source_joints, pair_record
from simdiff.data.augment.projector import Projector, SimProjector
from simdiff.data.writer import check_apart, write_bytes, write_json, write_lines
from simdiff.errors import SimdiffError
from simdiff.sim.env import GRAVITY_RANGE, Environment
from simdiff.sim.pool import WorkerDied, note_progress
from simdiff.sim.retime import RetimeConfig

BINARY_SIM_INDEX: int = 1
"""``env_index`` of simulated clips in binary mode (0 = source clips)."""
SHARD_DIR = "shards"
SETTINGS_NAME = "augment_settings.json"


@dataclass
class AugmentConfig:
    """Options of :func:`augment` (the CLI flags of ``simdiff data augment``).

    Attributes:
        mode: ``binary`` (Earth only) or ``random`` (``conditions`` one-factor environments).
        conditions: number of random conditions (paper: 30).
        seed: seeds the condition draw (the simulation itself is deterministic).
        split: source split to augment (``train``; never the test split).
        shard_size: source clips per shard (each shard holds shard_size × conditions pairs).
        limit: only the first ``limit`` clips of the split (smoke runs).
        filter: keep thresholds, applied at finalize (not part of :meth:`settings`).
        residual_bound: the tracker's root-residual bound (fraction of m·|g_z|; 0 = strict).
        workers, backend: parallelism of the default projector.
        per_clip: random mode only: project each clip under this many of the conditions
            (balanced round-robin over the split order) instead of all of them; None = all.
            Round-robin ties each condition to a fixed group of clips (φ confounded with
            content); ``paired`` mode draws per clip instead.
        share_mirrors: derive each mirrored clip ``M<id>`` (original in the split) from
            ``<id>``'s rollouts instead of simulating it (paired and binary modes); its
            conditions are then mirror(``<id>``'s), not independent draws.
        resimulate_gravity_below: after the shards are done, re-project the pairs with g_z
            below this (m/s²) that an older simulator version made, and their mirrors
            (:mod:`simdiff.data.augment.resim`; −9.81: the pairs the gravity-scaled actuators changed). Not a setting:
            a resumed run may add it. None: off.
        retime: under |g_z| < 9.81, retry a rollout that fell or strayed from the source's pose on
            the source slowed to the same Froude number and keep the better one
            (:mod:`simdiff.sim.retime`; records carry ``retime_scale``). A setting: a run made
            before it existed resumes only with ``retime=False``.
        factors: paired mode: the factors drawn (default all three; e.g. ``("gravity",)``).
        gravity_range: paired mode: ``(lo, hi)`` of the g_z draw, m/s² (default the validated range).

    Modes (:mod:`simdiff.data.augment.conditions`): ``paired`` (default; Earth + ``conditions``
    (default 6) draws per clip), ``paper`` (every clip under all ``conditions`` (30) random
    conditions), ``random`` (the same list, optionally ``per_clip``), ``binary`` (Earth).
    """

    mode: str = "paired"
    conditions: int | None = None
    seed: int = 0
    split: str = "train"
    shard_size: int = 4
    limit: int | None = None
    filter: FilterConfig = field(default_factory=FilterConfig)
    residual_bound: float = 0.5
    workers: int = 0
    backend: str = "process"
    per_clip: int | None = None
    share_mirrors: bool = False
    resimulate_gravity_below: float | None = None
    retime: bool = True
    factors: tuple[str, ...] = FACTORS
    gravity_range: tuple[float, float] = GRAVITY_RANGE

    def __post_init__(self) -> None:
        # one canonical form (FACTORS order, floats), so a resumed run's settings compare equal
        self.factors = check_factors(self.factors)
        self.gravity_range = check_gravity_range(self.gravity_range)
        if self.mode == "paired":  # a one-gravity range with too many draws fails here, before any file is written
            check_one_gravity(self.n_conditions, self.factors, self.gravity_range)

    @property
    def n_conditions(self) -> int:
        """``conditions`` with its mode's default (paired: 6 per clip; random/paper: 30; binary: 1)."""
        if self.mode == "binary":
            return 1
        if self.conditions is not None:
            return self.conditions
        return DEFAULT_PAIRED_K if self.mode == "paired" else 30

    def settings(self) -> dict[str, Any]:
        """The options a resumed run must share (parallelism, limit and filter thresholds may change)."""
        settings = {"mode": self.mode, "conditions": self.n_conditions,
                    "seed": self.seed, "split": self.split, "shard_size": self.shard_size,
                    "residual_bound": self.residual_bound}
        if self.per_clip is not None:
            settings["per_clip"] = self.per_clip
        if self.share_mirrors:
            settings["share_mirrors"] = True
        if self.retime:
            settings["retime"] = asdict(RetimeConfig())
        if self.factors != FACTORS:
            settings["factors"] = list(self.factors)
        if self.gravity_range != GRAVITY_RANGE:
            settings["gravity_range"] = list(self.gravity_range)
        return settings


def assign_conditions(clips: Sequence[str], conditions: Sequence[AugmentEnv], per_clip: int | None
                      ) -> dict[str, list[AugmentEnv]]:
    """Conditions each clip is projected under: all, or ``per_clip`` of them round-robin.

    Clip ``k`` of the split gets conditions ``k·per_clip … k·per_clip + per_clip − 1`` (mod the number
    of conditions), so every condition is used equally often and neighbouring (similar) clips differ.
    """
    if per_clip is None or per_clip >= len(conditions):
        return {c: list(conditions) for c in clips}
    if per_clip < 1:
        raise SimdiffError(f"--per-clip must be at least 1, got {per_clip}")
    n = len(conditions)
    return {c: [conditions[(k * per_clip + j) % n] for j in range(per_clip)] for k, c in enumerate(clips)}


def conditions_for(clips: Sequence[str], conditions: Sequence[AugmentEnv], config: AugmentConfig
                   ) -> dict[str, list[AugmentEnv]]:
    """Conditions of every clip under ``config``'s mode (paired: drawn per clip)."""
    if config.mode == "paired":
        out = {c: paired_conditions(c, config.n_conditions, config.seed, config.factors, config.gravity_range)
               for c in clips}
    else:
        out = assign_conditions(clips, conditions, config.per_clip if config.mode == "random" else None)
    if config.share_mirrors:
        for mx, x in mirror_sources(clips).items():
            out[mx] = [mirror_condition(c) for c in out[x]]
    return out


def env_index_for(mode: str, condition: AugmentEnv) -> int:
    """Categorical label of a simulated clip (see module docstring)."""
    return BINARY_SIM_INDEX if mode == "binary" else condition.index


def _shard_path(out: Path, index: int) -> Path:
    return out / SHARD_DIR / f"shard_{index:05d}.json"


def plan(corpus: Path, config: AugmentConfig) -> tuple[list[str], list[AugmentEnv], list[list[str]]]:
    """(clip ids, conditions, shards as lists of clip ids) for a run; validates the corpus."""
    from simdiff.data.humanml3d import read_split

    if not corpus.is_dir():
        raise SimdiffError(f"corpus directory not found: {corpus}")
    for name in ("Mean.npy", "Std.npy"):
        if not (corpus / name).is_file():
            raise SimdiffError(f"{corpus / name}: missing (the augmented corpus reuses the source Mean/Std)")
    if config.split == "test":
        raise SimdiffError("refusing to augment the test split (it must stay unseen)")
    if config.shard_size < 1:
        raise SimdiffError(f"shard size must be at least 1, got {config.shard_size}")
    if config.mode != "paired" and (config.factors != FACTORS or config.gravity_range != GRAVITY_RANGE):
        raise SimdiffError(f"--factors/--gravity-range narrow paired mode's draws; mode {config.mode!r} has none")
    clips = read_split(corpus / f"{config.split}.txt")
    if config.limit is not None:
        if config.limit < 1:
            raise SimdiffError(f"--limit must be at least 1, got {config.limit}")
        clips = clips[: config.limit]
    if not clips:
        raise SimdiffError(f"{corpus / (config.split + '.txt')}: no clips to augment")
    conditions = make_conditions(config.mode, config.n_conditions, config.seed)
    if config.filter.max_pose_d_l2 == AUTO and config.mode not in ("paired", "binary"):
        raise SimdiffError(f"--max-pose-d-l2 auto calibrates on Earth pairs, which {config.mode!r} mode does not "
                           "simulate; give a number")
    if config.share_mirrors:
        if config.mode not in ("paired", "binary"):
            raise SimdiffError(f"--share-mirrors needs paired or binary mode, got {config.mode!r} "
                               "(a shared condition list has no mirrored copy)")
        units = group_mirrors(clips)  # shard_size originals per shard, each with its mirror
        shards = [[c for u in units[i : i + config.shard_size] for c in u] for i in range(0, len(units), config.shard_size)]
        return [c for shard in shards for c in shard], conditions, shards
    shards = [clips[i : i + config.shard_size] for i in range(0, len(clips), config.shard_size)]
    return clips, conditions, shards


def _check_settings(out: Path, config: AugmentConfig, conditions: list[AugmentEnv]) -> None:
    settings = {**config.settings(), "condition_list": [c.to_dict() for c in conditions]}
    path = out / SETTINGS_NAME
    if path.is_file():
        old = {k: v for k, v in _read_json(path).items() if k != "filter"}  # older runs stored it
        if old != json.loads(json.dumps(settings)):
            changed = sorted(k for k in set(old) | set(settings) if old.get(k) != json.loads(json.dumps(settings)).get(k))
            raise SimdiffError(f"{out} was made with different settings ({', '.join(changed)}); use a new --out")
    else:
        write_json(path, settings)


def _run_shard(corpus: Path, out: Path, index: int, clips: list[str], assigned: dict[str, list[AugmentEnv]],
               config: AugmentConfig, projector: Projector, tick: Callable[[int], None]) -> dict[str, Any]:
    """Project one shard and write its tracked pairs' files; returns its record (written by the caller)."""
    from simdiff.data.augment.signal import measure

    motions, envs, pairs, load_errors, content = [], [], [], {}, {}
    derived = mirror_sources(clips) if config.share_mirrors else {}
    for clip in clips:
        conditions = assigned[clip]
        try:
            joints = load_source_joints(corpus, clip)
            content[clip] = measure(joints)
        except SimdiffError as exc:
            load_errors[clip] = str(exc)
            continue
        if derived.get(clip) in content:  # its original (earlier in the shard) loaded: derive, don't simulate
            continue
        for cond in conditions:
            motions.append(joints)
            envs.append(cond.env)
            pairs.append((clip, cond))
    derived = {mx: x for mx, x in derived.items() if mx in content and x in content}
    records: list[dict[str, Any]] = []
    for clip, message in load_errors.items():
        conditions = assigned[clip]
        for cond in conditions:
            records.append({"clip": clip, "condition": cond.index, "id": clip_id_for(clip, cond), "written": False,
                            "reason": "error", "info": message, "env": list(cond.env.as_tuple()), "factor": cond.factor})
        tick(len(conditions))
    results = iter(projector(motions, envs)) if motions else iter(())
    simulated: dict[tuple[str, int], tuple[Any, Any]] = {}
    for clip, cond in pairs:
        try:
            rollout, info = next(results)
        except StopIteration:
            raise SimdiffError(f"the projector returned fewer results than the {len(pairs)} motions given") from None
        simulated[(clip, cond.index)] = (rollout, info_dict(info))
        records.append(pair_record(corpus, out, clip, cond, rollout, info_dict(info), content.get(clip)))
        tick(1)
    for mx, x in derived.items():
        for cond in assigned[mx]:
            rollout, info = simulated[(x, cond.index)]
            record = pair_record(corpus, out, mx, cond, mirror_rollout(rollout), mirror_info(info, cond.env),
                                  content.get(mx))
            records.append({**record, "mirrored_from": clip_id_for(x, cond)})
            tick(1)
    order = {(c, k.index): i for i, (c, k) in enumerate((c, k) for c in clips for k in assigned[c])}
    records.sort(key=lambda r: order[(r["clip"], r["condition"])])
    return {"shard": index, "clips": clips, "records": records}


def augment(corpus: str | os.PathLike[str], out: str | os.PathLike[str], config: AugmentConfig = AugmentConfig(),
            projector: Projector | None = None, progress: bool = True) -> dict[str, Any]:
    """Build (or resume) a simulator-augmented corpus; returns the report (also in ``out/report.json``).

    Args:
        corpus: source corpus in the HumanML3D layout (Mean.npy, Std.npy, <split>.txt).
        out: output folder (created; resumed when it holds shards of the same settings).
        config: see :class:`AugmentConfig`.
        projector: injected projector (tests); default :class:`SimProjector` on ``corpus`` stats.
        progress: show a tqdm bar (pairs done, rate, ETA) on stderr.
    """
    from tqdm import tqdm

    corpus, out = Path(corpus), Path(out)
    check_apart(corpus, out, "--corpus", "--out")
    clips, conditions, shards = plan(corpus, config)
    out.mkdir(parents=True, exist_ok=True)
    _check_settings(out, config, conditions)
    assigned = conditions_for(clips, conditions, config)
    todo = []
    for i, shard in enumerate(shards):
        path = _shard_path(out, i)
        if not (path.is_file() and _read_json(path).get("clips") == shard):
            todo.append(i)
    own = projector is None
    proj: Projector = projector or SimProjector(str(corpus), config.workers, config.backend, config.residual_bound,
                                                 retime=RetimeConfig() if config.retime else None)
    total = sum(len(assigned[c]) for c in clips)
    done = sum(len(assigned[c]) for i in range(len(shards)) if i not in todo for c in shards[i])
    start = time.time()
    bar = tqdm(total=total, initial=done, desc="augment", unit="pair", disable=not progress, dynamic_ncols=True)
    clips_done = sum(len(shards[i]) for i in range(len(shards)) if i not in todo)
    try:
        for i in todo:
            record = _run_shard(corpus, out, i, shards[i], assigned, config, proj, bar.update)
            write_json(_shard_path(out, i), record)
            clips_done += len(shards[i])
        bar.close()
        if config.resimulate_gravity_below is not None:
            from simdiff.data.augment.resim import resimulate

            resimulate(corpus, out, [_shard_path(out, i) for i in range(len(shards))], proj,
                       config.resimulate_gravity_below, progress)
    except BaseException as exc:  # Ctrl-C, SIGTERM, a dead worker: stop the workers now, not after their pairs
        if own:
            getattr(proj, "terminate", lambda: None)()
        if isinstance(exc, (KeyboardInterrupt, WorkerDied)):
            note_progress(exc, f"{clips_done} of {len(clips)} clips done")
        raise
    finally:
        bar.close()
        if own:
            getattr(proj, "close", lambda: None)()
    return finalize(corpus, out, config, conditions, len(shards), wall_s=time.time() - start)


def finalize(corpus: Path, out: Path, config: AugmentConfig, conditions: Sequence[AugmentEnv], n_shards: int,
             wall_s: float = 0.0) -> dict[str, Any]:
    """Decide the kept pairs, write splits, env.json, Mean/Std and the report; drop orphan files.

    The decision (:func:`simdiff.data.augment.decide.decide`) uses ``config.filter`` on the
    records of this run's shards; files of tracked pairs stay whether kept or not.
    """
    records: list[dict[str, Any]] = []
    protected: set[str] = set()  # written ids of every finished shard, also those beyond this run's --limit
    for path in sorted((out / SHARD_DIR).glob("shard_*.json")):
        shard = _read_json(path)
        protected.update(r["id"] for r in shard["records"] if r.get("written", r.get("kept")))
        if int(shard["shard"]) < n_shards:
            records.extend(shard["records"])
    records, summary = decide(records, config.filter)
    kept = [r for r in records if r["kept"]]
    by_index = {c.index: c for c in conditions}

    def cond_of(r: dict[str, Any]) -> AugmentEnv:
        if "env" in r:  # the pair's own φ (paired mode draws per clip)
            return AugmentEnv(int(r["condition"]), str(r.get("factor", "")), Environment(*map(float, r["env"])))
        return by_index[r["condition"]]

    retimed = {r["id"]: float(r["info"]["retime_scale"]) for r in kept
               if float((r.get("info") or {}).get("retime_scale", 1.0)) != 1.0}
    env = {
        r["id"]: {"env": list(cond_of(r).env.as_tuple()), "env_index": env_index_for(config.mode, cond_of(r)),
                  "condition": r["condition"], "factor": cond_of(r).factor, "source": r["clip"],
                  **({"retime_scale": retimed[r["id"]]} if r["id"] in retimed else {})}
        for r in kept
    }
    ids = [r["id"] for r in kept]
    write_lines(out / "train.txt", ids)
    write_lines(out / "all.txt", ids)
    write_lines(out / "first_try.txt", [i for i in ids if i not in retimed])
    write_json(out / "env.json", env)
    write_json(out / "conditions.json", [c.to_dict() for c in conditions])
    from simdiff.model.provenance import SOURCE_CORPUS_NAME, source_record

    write_json(out / SOURCE_CORPUS_NAME, source_record(corpus, {r["clip"] for r in kept}))
    for name in ("Mean.npy", "Std.npy"):
        write_bytes(out / name, (corpus / name).read_bytes())
    keep_set = set(ids) | protected
    for sub, ext in (("new_joint_vecs", ".npy"), ("new_joints", ".npy"), ("texts", ".txt")):
        folder = out / sub
        if folder.is_dir():
            for path in folder.glob(f"*{ext}"):
                if path.stem not in keep_set:
                    path.unlink()
            folder.mkdir(exist_ok=True)
        else:
            folder.mkdir(parents=True)
    for folder in (out, out / SHARD_DIR, *(out / sub for sub in ("new_joint_vecs", "new_joints", "texts"))):
        for path in folder.glob(".*.tmp"):  # a write an interrupted run did not finish
            path.unlink(missing_ok=True)
    report = build_report(records, conditions, config, summary, motion_types=load_motion_types(corpus))
    report["wall_s_this_run"] = round(wall_s, 3)
    write_json(out / "report.json", report)
    write_text(out / "report.md", report_markdown(report))
    return report
