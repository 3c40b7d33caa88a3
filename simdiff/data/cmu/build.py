"""Build a HumanML3D-layout corpus from CMU mocap (``simdiff data build-cmu``).

For each trial: read its primary source (AMC > BVH > DeepMimic), retarget to the 22
HumanML3D joints at 20 fps, cut windows (:mod:`.windows`), run each window and its mirror
through :func:`simdiff.motion.features.process_joints` (canonical skeleton, floor,
facing +Z), and write ``new_joint_vecs/ID.npy`` (T-1, 263), ``new_joints/ID.npy``
(T-1, 22, 3, recovered from the features as HumanML3D does) and ``texts/ID.txt``.
Then: splits by trial, ``Mean.npy``/``Std.npy`` (grouped std over train) and
``manifest.json``.

Incremental: each finished trial leaves ``.build/trials/SS_TT.json`` keyed by a hash of
its source bytes and of every setting that changes its output; a re-run reuses it. A
file that cannot be read is recorded as skipped and never aborts the build.
"""

from __future__ import annotations

import hashlib
import json
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from simdiff.data.cmu import captions as cap
from simdiff.data.cmu.load import load_source, source_frame
from simdiff.data.cmu.sources import RIGS, Trial, discover
from simdiff.data.cmu.splits import assign_splits
from simdiff.data.cmu.windows import MAX_WINDOW, MIN_WINDOW, Window, plan_windows
from simdiff.data.cmu.writer import write_json
from simdiff.data.clip_files import (
    Pending, clip_variants, files_exist, ground_contact, load_record, remove_stale, support_of, write_clip,
    write_splits, write_stats,
)
from simdiff.errors import SimdiffError
from simdiff.fsio import file_digest
from simdiff.motion.skeleton import FPS

PIPELINE_VERSION: int = 3
"""Bump when the output of a trial changes for the same inputs (invalidates the cache)."""

BUILD_DIR: str = ".build"


@dataclass
class BuildConfig:
    """Settings of one build.

    Attributes:
        src: CMU source folder.
        out: output corpus folder (keep it outside the repository).
        seed: captions and free-trial split order.
        splits_dir: HumanML3D split files (default ``src/../humanml3d/splits``).
        generated_captions: sentences per clip made from the CMU description.
        mirror: also write mirrored ``M<id>`` clips.
        trials: only these trials (None: all).
        rigs: source kinds allowed as primary (best of those present is used).
        progress: show a tqdm bar.
    """

    src: Path
    out: Path
    seed: int = 0
    splits_dir: Path | None = None
    generated_captions: int = 3
    mirror: bool = True
    trials: list[str] | None = None
    rigs: tuple[str, ...] = RIGS
    progress: bool = True


@dataclass
class BuildResult:
    """Summary of a build: clip records, skipped trials and timings (seconds)."""

    clips: list[dict[str, Any]]
    skipped: list[dict[str, str]]
    reused: int = 0
    processed: int = 0
    elapsed: float = 0.0
    split_counts: dict[str, int] = field(default_factory=dict)


def _trial_key(trial: Trial, rig: str, cfg: BuildConfig) -> str:
    files = [trial.files[rig]] + ([trial.asf] if rig == "amc" and trial.asf else [])
    settings = {
        "version": PIPELINE_VERSION,
        "rig": rig,
        "seed": cfg.seed,
        "generated": cfg.generated_captions,
        "mirror": cfg.mirror,
        "window": [MIN_WINDOW, MAX_WINDOW],
        "fps": trial.capture_fps,
        "description": trial.description,
        "kitml": trial.kitml,
        "segments": [[s.hml_id, s.start20, s.end20] for s in trial.segments],
    }
    blob = json.dumps(settings, sort_keys=True) + file_digest([Path(p) for p in files])
    return hashlib.sha1(blob.encode()).hexdigest()


def kit_for_window(trial: Trial, window: Window) -> list[str]:
    """KIT-ML sentences whose time span covers at least half of the window."""
    start, stop = window.start / FPS, window.stop / FPS
    out: list[str] = []
    for entry in trial.kitml:
        a, b = float(entry["start"]), float(entry["end"])  # type: ignore[arg-type]
        if b <= a:  # no span given: the whole trial
            a, b = 0.0, float("inf")
        overlap = max(0.0, min(b, stop) - max(a, start))
        text = " ".join(str(entry["text"]).split())
        if overlap >= 0.5 * (stop - start) and text and text not in out:
            out.append(text)
    return out


def clip_captions(trial: Trial, window: Window, clip_id: str, cfg: BuildConfig) -> tuple[list[str], str]:
    """Captions of one clip and their origin ("kitml" or "generated")."""
    human = kit_for_window(trial, window)
    if human:
        return human, "kitml"
    return cap.describe(trial.description, n=cfg.generated_captions, seed=cfg.seed, key=clip_id), "generated"


def _relative(path: Path, root: Path) -> str:
    try:
        return str(path.relative_to(root))
    except ValueError:
        return path.name if path.parent.name != "bvh" else f"bvh/{path.name}"


def process_trial(trial: Trial, rig: str, cfg: BuildConfig) -> list[dict[str, Any]]:
    """Retarget, window, mirror and write every clip of a trial; returns clip records."""
    joints, skipped = load_source(trial, rig)
    windows = plan_windows(joints.shape[0], trial.segments)
    if not windows:
        raise SimdiffError(
            f"{trial.files[rig]}: {joints.shape[0]} frames at 20 fps, shorter than {MIN_WINDOW}"
        )
    kind = cap.motion_type(trial.description)
    records: list[dict[str, Any]] = []
    pending: list[Pending] = []
    for k, window in enumerate(windows):
        clip_id = f"{trial.trial}_{k:02d}"
        texts, origin = clip_captions(trial, window, clip_id, cfg)
        piece = joints[window.start : window.stop]
        base = {
            "trial": trial.trial,
            "rig": rig,
            "source": _relative(trial.files[rig], cfg.src),
            "start20": window.start,
            "stop20": window.stop,
            "source_frames": [source_frame(trial, rig, window.start, skipped), source_frame(trial, rig, window.stop, skipped)],
            "window": window.origin,
            "motion_type": kind,
            "caption_origin": origin,
            "description": trial.description,
        }
        contact = ground_contact(piece)  # trial joints have the trial's floor at y = 0
        base["ground_contact"] = round(contact, 3)
        base["support"] = support_of(contact)
        new_records, new_pending = clip_variants(base, clip_id, piece, texts, cfg.mirror, cap.caption_line)
        records += new_records
        pending += new_pending
    for cid, features, recovered, lines in pending:  # only once every clip of the trial worked
        write_clip(cfg.out, cid, features, recovered, lines)
    return records


def build_corpus(cfg: BuildConfig) -> BuildResult:
    """Build (or update) the corpus in ``cfg.out``; see the module docstring."""
    from tqdm import tqdm

    started = time.perf_counter()
    cfg.src, cfg.out = Path(cfg.src), Path(cfg.out)
    cache = cfg.out / BUILD_DIR
    (cache / "trials").mkdir(parents=True, exist_ok=True)
    trials = discover(cfg.src, cache, cfg.splits_dir)
    if cfg.trials:
        wanted = set(cfg.trials)
        unknown = wanted - {t.trial for t in trials}
        if unknown:
            raise SimdiffError(f"unknown trial(s) in {cfg.src}: {', '.join(sorted(unknown))}")
        trials = [t for t in trials if t.trial in wanted]

    clips: list[dict[str, Any]] = []
    skipped: list[dict[str, str]] = []
    reused = processed = 0
    stale: set[str] = set()
    bar = tqdm(trials, desc="build-cmu", unit="trial", disable=not cfg.progress, dynamic_ncols=True)
    unknown_rigs = set(cfg.rigs) - set(RIGS)
    if unknown_rigs or not cfg.rigs:
        raise SimdiffError(f"unknown source kind(s) {sorted(unknown_rigs)}; choose from {', '.join(RIGS)}")
    for trial in bar:
        rig = trial.primary(tuple(cfg.rigs))
        if rig is None:
            if not any(r in trial.files for r in cfg.rigs):
                continue  # only in sources left out on purpose
            reason = "AMC without its ASF skeleton" if "amc" in trial.files else "no readable source"
            skipped.append({"trial": trial.trial, "error": reason})
            continue
        record_path = cache / "trials" / f"{trial.trial}.json"
        try:
            key = _trial_key(trial, rig, cfg)
        except OSError as exc:
            skipped.append({"trial": trial.trial, "error": f"{trial.files[rig]}: {exc.strerror}"})
            continue
        record = load_record(record_path)
        if record:
            stale.update(str(c["id"]) for c in record.get("clips", []))
        if record and record.get("key") == key and (record.get("error") or files_exist(cfg.out, record["clips"])):
            reused += 1
        else:
            bar.set_postfix_str(f"{trial.trial} {rig}")
            try:
                record = {"key": key, "trial": trial.trial, "error": None, "clips": process_trial(trial, rig, cfg)}
                write_json(record_path, record)
            except SimdiffError as exc:  # a bad input file: remembered until the file changes
                record = {"key": key, "trial": trial.trial, "error": str(exc), "clips": []}
                write_json(record_path, record)
            except Exception as exc:  # anything else: reported, not cached, retried next run
                error = f"{trial.files[rig]}: {type(exc).__name__}: {exc}".splitlines()[0]
                record = {"key": key, "trial": trial.trial, "error": error, "clips": []}
            processed += 1
        if record.get("error"):
            skipped.append({"trial": trial.trial, "error": str(record["error"])})
        clips.extend(record["clips"])
    bar.close()
    if not clips:
        raise SimdiffError(f"no clip could be built from {cfg.src} ({len(skipped)} trial(s) skipped)")

    durations: dict[str, float] = {}
    hml3d: dict[str, set[str]] = {t.trial: t.hml3d_splits for t in trials}
    for clip in clips:
        if clip["mirror_of"] is None:
            durations[clip["trial"]] = durations.get(clip["trial"], 0.0) + clip["seconds"]
    split_of = assign_splits(durations, hml3d, seed=cfg.seed)
    ids = write_splits(cfg.out, clips, split_of)
    remove_stale(cfg.out, {c["id"] for c in clips}, stale)
    write_stats(cfg.out, ids["train"])

    result = BuildResult(clips=clips, skipped=skipped, reused=reused, processed=processed,
                         split_counts={k: len(v) for k, v in ids.items()})
    write_json(cfg.out / "manifest.json", {
        "format": "simdiff-cmu-corpus",
        "pipeline_version": PIPELINE_VERSION,
        "src": str(cfg.src.resolve()),
        "seed": cfg.seed,
        "rigs": list(cfg.rigs),
        "fps": FPS,
        "counts": {
            "clips": len(clips),
            "trials": len(durations),
            "skipped_trials": len(skipped),
            "splits": result.split_counts,
            "hours": round(sum(c["seconds"] for c in clips) / 3600, 4),
        },
        "clips": sorted(clips, key=lambda c: c["id"]),
        "skipped": skipped,
    })
    result.elapsed = time.perf_counter() - started
    return result
