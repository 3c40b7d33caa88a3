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

import numpy as np

from simdiff.data.cmu import captions as cap
from simdiff.data.cmu.load import load_source, source_frame
from simdiff.data.cmu.sources import RIGS, Trial, discover
from simdiff.data.cmu.splits import SPLIT_NAMES, assign_splits
from simdiff.data.cmu.windows import MAX_WINDOW, MIN_WINDOW, Window, plan_windows
from simdiff.data.cmu.writer import write_json, write_lines, write_npy, write_text
from simdiff.errors import SimdiffError
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


def _digest(paths: list[Path]) -> str:
    sha = hashlib.sha1()
    for path in paths:
        with open(path, "rb") as handle:
            for block in iter(lambda: handle.read(1 << 20), b""):
                sha.update(block)
    return sha.hexdigest()


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
    blob = json.dumps(settings, sort_keys=True) + _digest([Path(p) for p in files])
    return hashlib.sha1(blob.encode()).hexdigest()


CONTACT_HEIGHT: float = 0.15
"""A frame touches the ground when its lowest joint is within this height (m) of the trial's floor."""
MIN_GROUND_FRACTION: float = 0.5
"""Clips whose fraction of ground-touching frames is below this are marked ``support: props``."""


def ground_contact(joints: np.ndarray, floor: float = 0.0) -> float:
    """Fraction of frames of (T, 22, 3) joints whose lowest joint is within
    :data:`CONTACT_HEIGHT` of ``floor`` (the trial's floor, not the clip's own lowest joint)."""
    lowest = np.asarray(joints, dtype=np.float64)[..., 1].min(axis=-1)
    return float(np.mean(lowest - floor <= CONTACT_HEIGHT)) if lowest.size else 0.0


def support_of(contact: float) -> str:
    """"floor" when the body stands on the ground most of the clip, else "props" (hanging
    from bars or playground equipment, sitting on a prop): physics augmentation skips those."""
    return "floor" if contact >= MIN_GROUND_FRACTION else "props"


def _kit_for_window(trial: Trial, window: Window) -> list[str]:
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
    human = _kit_for_window(trial, window)
    if human:
        return human, "kitml"
    return cap.describe(trial.description, n=cfg.generated_captions, seed=cfg.seed, key=clip_id), "generated"


def _relative(path: Path, root: Path) -> str:
    try:
        return str(path.relative_to(root))
    except ValueError:
        return path.name if path.parent.name != "bvh" else f"bvh/{path.name}"


def _process_clip(clip_id: str, joints: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Features (n-1, 263) and the joints they give back (n-1, 22, 3) of (n, 22, 3) joints."""
    from simdiff.motion.features import features_to_joints, process_joints

    features = process_joints(joints).features.astype(np.float32)
    if not np.all(np.isfinite(features)):
        raise SimdiffError(f"clip {clip_id}: non-finite features")
    return features, np.asarray(features_to_joints(features), dtype=np.float32)


def _write_clip(out: Path, clip_id: str, features: np.ndarray, joints: np.ndarray, lines: list[str]) -> None:
    """Write one clip's three files (atomically each)."""
    write_npy(out / "new_joint_vecs" / f"{clip_id}.npy", features)
    write_npy(out / "new_joints" / f"{clip_id}.npy", joints)
    write_text(out / "texts" / f"{clip_id}.txt", "".join(f"{line}\n" for line in lines))


def process_trial(trial: Trial, rig: str, cfg: BuildConfig) -> list[dict[str, Any]]:
    """Retarget, window, mirror and write every clip of a trial; returns clip records."""
    from simdiff.motion.mirror import mirror_caption, mirror_joints

    joints, skipped = load_source(trial, rig)
    windows = plan_windows(joints.shape[0], trial.segments)
    if not windows:
        raise SimdiffError(
            f"{trial.files[rig]}: {joints.shape[0]} frames at 20 fps, shorter than {MIN_WINDOW}"
        )
    kind = cap.motion_type(trial.description)
    records: list[dict[str, Any]] = []
    pending: list[tuple[str, np.ndarray, np.ndarray, list[str]]] = []
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
        variants = [(clip_id, piece, texts, None)]
        if cfg.mirror:
            variants.append((f"M{clip_id}", mirror_joints(piece), [mirror_caption(t) for t in texts], clip_id))
        for cid, motion, sentences, parent in variants:
            features, recovered = _process_clip(cid, motion)
            pending.append((cid, features, recovered, [cap.caption_line(s) for s in sentences]))
            rows = int(features.shape[0])
            records.append({**base, "id": cid, "mirror_of": parent, "frames": rows,
                            "seconds": round(rows / FPS, 3), "captions": sentences})
    for cid, features, recovered, lines in pending:  # only once every clip of the trial worked
        _write_clip(cfg.out, cid, features, recovered, lines)
    return records


def _load_record(path: Path) -> dict[str, Any] | None:
    try:
        return json.loads(path.read_text())
    except (OSError, ValueError):
        return None


def _files_exist(out: Path, clips: list[dict[str, Any]]) -> bool:
    return all(
        (out / sub / f"{c['id']}{ext}").is_file()
        for c in clips
        for sub, ext in (("new_joint_vecs", ".npy"), ("new_joints", ".npy"), ("texts", ".txt"))
    )


def _remove_stale(out: Path, keep: set[str], candidates: set[str]) -> int:
    """Delete clip files once written by this tool (previous manifest or trial records) but not produced now."""
    old = _load_record(out / "manifest.json")
    candidates = candidates | {str(c.get("id", "")) for c in (old or {}).get("clips", [])}
    removed = 0
    for cid in sorted(candidates):
        if cid and cid not in keep and "/" not in cid and ".." not in cid:
            for sub, ext in (("new_joint_vecs", ".npy"), ("new_joints", ".npy"), ("texts", ".txt")):
                path = out / sub / f"{cid}{ext}"
                if path.is_file():
                    path.unlink()
                    removed += 1
    return removed


def _write_stats(out: Path, train_ids: list[str]) -> None:
    """Mean.npy / Std.npy with HumanML3D's grouped std over the train clips."""
    from simdiff.motion.normalize import group_std

    if not train_ids:
        raise SimdiffError(f"no train clips in {out}: cannot compute Mean/Std")
    mean, std = group_std(np.load(out / "new_joint_vecs" / f"{cid}.npy") for cid in train_ids)
    std = np.where(std < 1e-6, 1e-6, std).astype(np.float32)  # a constant group (e.g. no contact) must not divide by 0
    write_npy(out / "Mean.npy", mean.astype(np.float32))
    write_npy(out / "Std.npy", std)


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
        record = _load_record(record_path)
        if record:
            stale.update(str(c["id"]) for c in record.get("clips", []))
        if record and record.get("key") == key and (record.get("error") or _files_exist(cfg.out, record["clips"])):
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
    ids: dict[str, list[str]] = {name: [] for name in SPLIT_NAMES}
    for clip in clips:
        clip["split"] = split_of[clip["trial"]]
        ids[clip["split"]].append(clip["id"])
    for name in SPLIT_NAMES:
        ids[name].sort()
        write_lines(cfg.out / f"{name}.txt", ids[name])
    write_lines(cfg.out / "train_val.txt", sorted(ids["train"] + ids["val"]))
    write_lines(cfg.out / "all.txt", sorted(c["id"] for c in clips))
    _remove_stale(cfg.out, {c["id"] for c in clips}, stale)
    _write_stats(cfg.out, ids["train"])

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
