"""``simdiff data build``: one HumanML3D-layout corpus from every source under a shared root.

Steps: discover items (:mod:`.registry`: licence filter, dedupe), process each item in a
process pool (:func:`.clips.process_item`; output independent of the worker count), split by
trial (:mod:`.splits`), write ``Mean.npy``/``Std.npy`` over train, split lists and
``manifest.json``. Resumable: each finished item leaves ``.build/items/<id>.json`` keyed by
its source bytes and every setting that changes its clips; a re-run reuses it. Files are
written atomically; a rerun gives byte-identical outputs.
"""

from __future__ import annotations

import hashlib
import json
import os
import time
from concurrent.futures import ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from simdiff.data.clip_files import (
    files_exist,
    load_record,
    remove_stale,
    write_splits,
    write_stats,
)
from simdiff.data.corpus.clips import ClipSettings, process_item, source_relative
from simdiff.data.corpus.item import Item
from simdiff.data.corpus.registry import SOURCES, discover_all
from simdiff.data.corpus.splits import assign_stratified
from simdiff.data.corpus.windows import MAX_WINDOW, MIN_WINDOW
from simdiff.data.writer import check_apart, cleaned_on_failure, write_json
from simdiff.errors import SimdiffError
from simdiff.fsio import file_digest
from simdiff.licences import LICENCE_SETS
from simdiff.motion.skeleton import FPS

MIN_CAPTIONS, MAX_CAPTIONS = 2, 10
"""Generated captions per clip: at least 2 (HumanML3D's minimum), at most 10."""

PIPELINE_VERSION: int = 2
"""Bump when an item's clips change for the same inputs (invalidates the item cache)."""

FORMAT: str = "simdiff-corpus"

BUILD_DIR: str = ".build"
"""Per-item cache folder inside the output corpus."""


@dataclass
class CorpusConfig:
    """Settings of one build.

    Attributes:
        shared: shared data root (``../shared/data``).
        out: output corpus folder (outside the repository).
        licence: ``all`` or ``permissive`` (see :data:`.item.LICENCE_SETS`).
        sources: source families (default all of :data:`.registry.SOURCES`).
        workers: processes, 0..64 (0: one per CPU core; 1: in this process); the output does not depend on it.
        seed: captions and split order.
        captions: generated sentences per clip.
        mirror: write mirrored ``M<id>`` clips.
        progress: show a tqdm bar.
    """

    shared: Path
    out: Path
    licence: str = "all"
    sources: tuple[str, ...] = tuple(SOURCES)
    workers: int = 2
    seed: int = 0
    captions: int = 3
    mirror: bool = True
    progress: bool = True


@dataclass
class CorpusResult:
    """Summary of a build: clip records, skipped items and timings (seconds)."""

    clips: list[dict[str, Any]]
    skipped: list[dict[str, str]]
    reused: int = 0
    processed: int = 0
    elapsed: float = 0.0
    split_counts: dict[str, int] = field(default_factory=dict)


def code_digest() -> str:
    """SHA-1 of the readers and retargeting code (``simdiff/motion/io``): a reader change
    invalidates the item cache without a :data:`PIPELINE_VERSION` bump."""
    import simdiff.motion.io as io_package

    root = Path(io_package.__file__).parent
    return file_digest(sorted(root.rglob("*.py")))


def item_key(item: Item, settings: ClipSettings, code: str = "") -> str:
    """Cache key of an item: its source bytes, the reader code and every setting that changes its clips."""
    trial = item.meta.get("cmu_trial")
    payload = {
        "version": PIPELINE_VERSION, "id": item.id, "trial": item.trial, "source": item.source,
        "licence": item.licence, "type": item.motion_type, "verbs": item.verbs, "adverbs": item.adverbs,
        "subjects": item.subjects, "origin": item.caption_origin, "description": item.description,
        "fps": item.fps, "seed": settings.seed, "captions": settings.captions, "mirror": settings.mirror,
        "window": [MIN_WINDOW, MAX_WINDOW], "code": code,
    }
    if trial is not None:
        payload["cmu"] = {
            "description": trial.description, "kitml": trial.kitml, "fps": trial.capture_fps,  # type: ignore[attr-defined]
            "segments": [[s.hml_id, s.start20, s.end20] for s in trial.segments],  # type: ignore[attr-defined]
        }
    blob = json.dumps(payload, sort_keys=True, default=str) + file_digest(item.files())
    return hashlib.sha1(blob.encode()).hexdigest()


def _run_item(item: Item, settings: ClipSettings) -> tuple[list[dict[str, Any]], str | None, bool]:
    """(records, error, cacheable) of one item; never raises."""
    try:
        return process_item(item, settings), None, True
    except SimdiffError as exc:
        return [], str(exc).splitlines()[0], True
    except Exception as exc:  # anything else: reported, not cached, retried next run
        return [], f"{item.path}: {type(exc).__name__}: {exc}".splitlines()[0], False


def _run_pool(todo: list[tuple[Item, str]], settings: ClipSettings, workers: int, finish: Any) -> None:
    """Process ``todo`` in ``workers`` processes, ``finish`` each result in order; on Ctrl-C, SIGTERM
    or a dead worker (one-line ``WorkerDied``) the workers are terminated at once."""
    from simdiff.sim.pool import (
        stop_workers,
        worker_died,
        worker_init_quiet,
        workers_starting,
    )

    pool = ProcessPoolExecutor(max_workers=workers, initializer=worker_init_quiet, initargs=(os.getpid(),))
    processes: list[Any] = []
    try:
        with workers_starting():  # the workers start here and keep SIGINT ignored: Ctrl-C is the parent's
            futures = [(item, key, pool.submit(_run_item, item, settings)) for item, key in todo]
        processes = list((getattr(pool, "_processes", None) or {}).values())
        for item, key, future in futures:
            try:
                result = future.result()
            except BrokenProcessPool:
                raise worker_died(processes) from None
            finish(item, key, result)
    except BaseException:
        stop_workers(pool, processes)
        raise
    pool.shutdown(wait=True)


def _alternates(item: Item, shared: Path) -> list[dict[str, Any]]:
    return [{"source": a.source, "file": source_relative(a.path, shared)} for a in item.alternates]


def build(cfg: CorpusConfig) -> CorpusResult:
    """Build (or update) the corpus in ``cfg.out``; see the module docstring. A build that fails before any item
    is done removes the folders it created; ``--out`` must be apart from ``--shared``."""
    started = time.perf_counter()
    shared, out = Path(cfg.shared), Path(cfg.out)
    from simdiff.sim.pool import MAX_WORKERS

    if not 0 <= cfg.workers <= MAX_WORKERS:
        raise SimdiffError(f"--workers must be 0 (one per CPU core) to {MAX_WORKERS}, got {cfg.workers}")
    if not MIN_CAPTIONS <= cfg.captions <= MAX_CAPTIONS:
        raise SimdiffError(f"--captions must be {MIN_CAPTIONS} to {MAX_CAPTIONS}, got {cfg.captions}")
    workers = cfg.workers or os.cpu_count() or 1
    if cfg.licence not in LICENCE_SETS:
        raise SimdiffError(f"unknown licence set {cfg.licence!r}; choose from {', '.join(LICENCE_SETS)}")
    check_apart(shared, out, "--shared", "--out")
    cache = out / BUILD_DIR
    records: dict[str, dict[str, Any]] = {}
    with cleaned_on_failure(cache / "items", keep=lambda: bool(records)):  # keep only resumable work
        return _build_items(cfg, shared, out, cache, workers, records, started)


def _build_items(cfg: CorpusConfig, shared: Path, out: Path, cache: Path, workers: int,
                 records: dict[str, dict[str, Any]], started: float) -> CorpusResult:
    """Discover, process (or reuse) and finish every item of a build whose cache folder exists."""
    from tqdm import tqdm

    items = discover_all(shared, cache, cfg.sources, cfg.licence)
    if not items:
        raise SimdiffError(f"no motion files for sources {', '.join(cfg.sources)} under {shared}")
    settings = ClipSettings(out=out, shared=shared, seed=cfg.seed, captions=cfg.captions, mirror=cfg.mirror)

    todo: list[tuple[Item, str]] = []
    stale: set[str] = set()
    reused = 0
    code = code_digest()
    for item in items:
        key = item_key(item, settings, code)
        record = load_record(cache / "items" / f"{item.id}.json")
        if record:
            stale.update(str(c["id"]) for c in record.get("clips", []))
        if record and record.get("key") == key and (record.get("error") or files_exist(out, record["clips"])):
            records[item.id] = record
            reused += 1
        else:
            todo.append((item, key))

    bar = tqdm(total=len(todo), desc="build", unit="item", disable=not cfg.progress, dynamic_ncols=True)

    def finish(item: Item, key: str, result: tuple[list[dict[str, Any]], str | None, bool]) -> None:
        clips, error, cacheable = result
        record = {"key": key, "id": item.id, "error": error, "clips": clips}
        if cacheable:
            write_json(cache / "items" / f"{item.id}.json", record)
        records[item.id] = record
        bar.update(1)

    try:
        if workers == 1 or len(todo) <= 1:
            for item, key in todo:
                finish(item, key, _run_item(item, settings))
        else:
            _run_pool(todo, settings, workers, finish)
    except BaseException as exc:  # Ctrl-C, SIGTERM, a dead worker: finished items are cached, a rerun resumes
        from simdiff.sim.pool import WorkerDied, note_progress

        if isinstance(exc, (KeyboardInterrupt, WorkerDied)):
            note_progress(exc, f"{len(records)} of {len(items)} items done")
        raise
    finally:
        bar.close()
    return _finish(cfg, items, records, stale, reused, len(todo), started)


def _finish(cfg: CorpusConfig, items: list[Item], records: dict[str, dict[str, Any]], stale: set[str],
            reused: int, processed: int, started: float) -> CorpusResult:
    """Splits, split lists, Mean/Std and the manifest from the item records."""
    out, shared = Path(cfg.out), Path(cfg.shared)
    clips: list[dict[str, Any]] = []
    skipped: list[dict[str, str]] = []
    durations: dict[str, float] = {}
    strata: dict[str, str] = {}
    fixed: dict[str, str] = {}
    for item in items:
        record = records[item.id]
        if record.get("error"):
            skipped.append({"id": item.id, "trial": item.trial, "error": str(record["error"])})
            continue
        for clip in record["clips"]:
            clip["alternates"] = _alternates(item, shared)
            clips.append(clip)
            if clip["mirror_of"] is None:
                durations[item.trial] = durations.get(item.trial, 0.0) + float(clip["seconds"])
        strata[item.trial] = f"{item.source.split('-')[0]}/{item.motion_type}"
        trial = item.meta.get("cmu_trial")
        labels = trial.hml3d_splits if trial is not None and item.source in ("cmu-amc", "cmu-bvh", "cmu-deepmimic") else set()  # type: ignore[attr-defined]
        hml = next((s for s in ("test", "val", "train") if s in labels), None)
        if hml:
            fixed[item.trial] = hml
    if not clips:
        raise SimdiffError(f"no clip could be built from {shared} ({len(skipped)} item(s) skipped)")
    split_of = assign_stratified(durations, strata, fixed, seed=cfg.seed)
    ids = write_splits(out, clips, split_of)
    remove_stale(out, {c["id"] for c in clips}, stale)
    write_stats(out, ids["train"])
    result = CorpusResult(clips=clips, skipped=skipped, reused=reused, processed=processed,
                          split_counts={k: len(v) for k, v in ids.items()})
    by_licence: dict[str, float] = {}
    for clip in clips:
        if clip["mirror_of"] is None:
            by_licence[clip["licence"]] = by_licence.get(clip["licence"], 0.0) + float(clip["seconds"]) / 3600
    write_json(out / "manifest.json", {
        "format": FORMAT,
        "pipeline_version": PIPELINE_VERSION,
        "src": str((shared / "cmu").resolve()),
        "shared": str(shared.resolve()),
        "licence": cfg.licence,
        "sources": list(cfg.sources),
        "seed": cfg.seed,
        "fps": FPS,
        "counts": {
            "clips": len(clips), "trials": len(durations), "skipped_items": len(skipped),
            "splits": result.split_counts,
            "hours": round(sum(float(c["seconds"]) for c in clips) / 3600, 4),
            "hours_originals": round(sum(float(c["seconds"]) for c in clips if c["mirror_of"] is None) / 3600, 4),
            "hours_originals_by_licence": {k: round(v, 4) for k, v in sorted(by_licence.items())},
        },
        "clips": sorted(clips, key=lambda c: c["id"]),
        "skipped": sorted(skipped, key=lambda s: s["id"]),
    })
    result.elapsed = time.perf_counter() - started
    return result
