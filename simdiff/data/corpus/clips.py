"""Turn one loaded item into clips: windows, captions, mirrors, features, files."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from simdiff.data.clip_files import Pending, clip_variants, ground_contact, support_of, write_clip
from simdiff.data.corpus import cmu_captions
from simdiff.data.corpus.windows import MIN_WINDOW, Window, plan_windows
from simdiff.data.corpus.item import Item
from simdiff.data.corpus.load import load_item, source_fps
from simdiff.data.corpus.phrasing import sentences
from simdiff.errors import SimdiffError
from simdiff.motion.skeleton import FPS

MIN_CAPTIONS: int = 2
"""Every clip gets at least this many sentences."""
MIN_TAKE: int = 10
"""Takes of at least this many 20 fps frames (0.5 s) but under a window (2 s) are padded."""


def pad_short(joints: np.ndarray, min_len: int = MIN_WINDOW) -> tuple[np.ndarray, int]:
    """Hold the first and last pose of a (T, 22, 3) take shorter than ``min_len`` frames
    (half the missing frames before, half after) so that it makes one clip; returns the
    padded joints and the frames added before. HDM05 cut takes (one hop, one kick) and
    DeepMimic loops (a backflip, 1.85 s) are that short; the holds are standing poses."""
    missing = min_len - joints.shape[0]
    if missing <= 0:
        return joints, 0
    before = missing // 2
    after = missing - before
    padded = np.concatenate([np.repeat(joints[:1], before, 0), joints, np.repeat(joints[-1:], after, 0)])
    return padded.astype(np.float32), before


@dataclass(frozen=True)
class ClipSettings:
    """Settings that change a clip's output (part of the cache key).

    Attributes:
        out: corpus folder.
        shared: shared data root (manifest paths are relative to it).
        seed: caption seed.
        captions: generated sentences per clip.
        mirror: also write ``M<id>`` mirrors.
    """

    out: Path
    shared: Path
    seed: int = 0
    captions: int = 3
    mirror: bool = True


def window_captions(item: Item, window: Window, clip_id: str, cfg: ClipSettings) -> tuple[list[str], str]:
    """Sentences of one clip (>= :data:`MIN_CAPTIONS`) and their origin."""
    n = max(cfg.captions, MIN_CAPTIONS)
    trial = item.meta.get("cmu_trial")
    if trial is not None:
        human = cmu_captions.kit_for_window(trial, window)  # type: ignore[arg-type]
        generated = cmu_captions.describe(trial.description, n=n, seed=cfg.seed, key=clip_id)  # type: ignore[attr-defined]
        if len(human) >= MIN_CAPTIONS:
            return human, "kitml"
        if human:
            return human + [s for s in generated if s not in human][: MIN_CAPTIONS - len(human)], "kitml+cmu-description"
        return generated, "cmu-description"
    return sentences(item.verbs, adverbs=item.adverbs, subjects=item.subjects, n=n, seed=cfg.seed,
                     key=clip_id), item.caption_origin


def source_relative(path: Path, shared: Path) -> str:
    """Path of a source file relative to the shared root ("extra/<archive>/..." when extracted)."""
    try:
        return str(path.resolve().relative_to(shared.resolve()))
    except ValueError:
        parts = path.parts
        if "extract" in parts:  # cache/extract/<name>/... came from extra/<name>.tar.xz
            k = len(parts) - 1 - parts[::-1].index("extract")
            return "extra/" + "/".join(parts[k + 1 :])
        if "bvh" in parts:  # shared/cmu/bvh.tar.xz extracted into the cache
            return f"cmu/bvh.tar.xz:{path.name}"
        return path.name


def process_item(item: Item, cfg: ClipSettings) -> list[dict[str, Any]]:
    """Load, window, caption, mirror and write every clip of ``item``; returns clip records.

    Raises:
        SimdiffError: unreadable or too short source (files are written only when all clips work).
    """
    joints, skipped = load_item(item)
    taken = joints.shape[0]
    before = 0
    if MIN_TAKE <= taken < MIN_WINDOW:
        joints, before = pad_short(joints)
    padded = joints.shape[0] - taken
    trial = item.meta.get("cmu_trial")
    segments = list(getattr(trial, "segments", [])) if item.source in ("cmu-amc", "cmu-bvh", "cmu-deepmimic") else []
    windows = plan_windows(joints.shape[0], segments)
    if not windows:
        raise SimdiffError(f"{item.path}: {taken} frames at 20 fps, shorter than {MIN_TAKE / FPS:g} s")
    fps = source_fps(item)
    records: list[dict[str, Any]] = []
    pending: list[Pending] = []
    for k, window in enumerate(windows):
        clip_id = f"{item.id}_{k:02d}"
        texts, origin = window_captions(item, window, clip_id, cfg)
        if len(texts) < MIN_CAPTIONS:
            raise SimdiffError(f"{item.path}: only {len(texts)} caption(s) for {clip_id}")
        piece = joints[window.start : window.stop]
        contact = ground_contact(piece)
        base = {
            "trial": item.trial, "source": item.source, "rig": item.source, "licence": item.licence,
            "motion_type": item.motion_type, "caption_origin": origin, "description": item.description,
            "file": source_relative(item.path, cfg.shared), "fps": fps, "start20": window.start, "stop20": window.stop,
            "source_frames": None if fps is None else [  # held (padded) frames map to the take's ends
                int(round(min(max(t - before, 0), taken) * fps / FPS)) + skipped for t in (window.start, window.stop)],
            "window": window.origin, "padded_frames": padded,
            "ground_contact": round(contact, 3), "support": support_of(contact),
        }
        new_records, new_pending = clip_variants(base, clip_id, piece, texts, cfg.mirror, cmu_captions.caption_line)
        records += new_records
        pending += new_pending
    for cid, features, recovered, lines in pending:
        write_clip(cfg.out, cid, features, recovered, lines)
    return records
