"""Clips of a HumanML3D-layout corpus on disk.

Used by ``simdiff data build`` (:mod:`simdiff.data.corpus.build`) and ``simdiff data loop``
(:mod:`simdiff.data.loop`): ground contact of a window, features of a clip and its
mirror, the three files of a clip (``new_joint_vecs/ID.npy`` (T-1, 263),
``new_joints/ID.npy`` (T-1, 22, 3) metres Y-up 20 fps, ``texts/ID.txt``), the per-item cache
records, split lists, stale-file removal and ``Mean.npy``/``Std.npy``.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from simdiff.data.corpus.splits import SPLIT_NAMES
from simdiff.data.writer import write_lines, write_npy, write_text
from simdiff.errors import SimdiffError
from simdiff.motion.skeleton import FPS

CONTACT_HEIGHT: float = 0.15
"""A frame touches the ground when its lowest joint is within this height (m) of the trial's floor."""
MIN_GROUND_FRACTION: float = 0.5
"""Clips whose fraction of ground-touching frames is below this are marked ``support: props``."""
CLIP_FILES: tuple[tuple[str, str], ...] = (("new_joint_vecs", ".npy"), ("new_joints", ".npy"), ("texts", ".txt"))
"""(folder, suffix) of the three files of a clip."""

Pending = tuple[str, np.ndarray, np.ndarray, list[str]]
"""(clip id, features, recovered joints, caption lines) of a clip not written yet."""


def ground_contact(joints: np.ndarray, floor: float = 0.0) -> float:
    """Fraction of frames of (T, 22, 3) joints whose lowest joint is within
    :data:`CONTACT_HEIGHT` of ``floor`` (the trial's floor, not the clip's own lowest joint)."""
    lowest = np.asarray(joints, dtype=np.float64)[..., 1].min(axis=-1)
    return float(np.mean(lowest - floor <= CONTACT_HEIGHT)) if lowest.size else 0.0


def support_of(contact: float) -> str:
    """"floor" when the body stands on the ground most of the clip, else "props" (hanging
    from bars or playground equipment, sitting on a prop): physics augmentation skips those."""
    return "floor" if contact >= MIN_GROUND_FRACTION else "props"


def process_clip(clip_id: str, joints: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Features (n-1, 263) and the joints they give back (n-1, 22, 3) of (n, 22, 3) joints."""
    from simdiff.motion.features import features_to_joints, process_joints

    features = process_joints(joints).features.astype(np.float32)
    if not np.all(np.isfinite(features)):
        raise SimdiffError(f"clip {clip_id}: non-finite features")
    return features, np.asarray(features_to_joints(features), dtype=np.float32)


def clip_variants(base: dict[str, Any], clip_id: str, piece: np.ndarray, texts: list[str], mirror: bool,
                  caption_line: Callable[[str], str]) -> tuple[list[dict[str, Any]], list[Pending]]:
    """Records and pending files of a window (n, 22, 3) and, with ``mirror``, its ``M<id>`` mirror.

    Each record is ``base`` plus id, mirror_of, frames, seconds and captions; features are
    computed here, files are written later by :func:`write_clip` (once every clip of the item worked).
    """
    from simdiff.motion.mirror import mirror_caption, mirror_joints

    variants = [(clip_id, piece, texts, None)]
    if mirror:
        variants.append((f"M{clip_id}", mirror_joints(piece), [mirror_caption(t) for t in texts], clip_id))
    records: list[dict[str, Any]] = []
    pending: list[Pending] = []
    for cid, motion, lines, parent in variants:
        features, recovered = process_clip(cid, motion)
        pending.append((cid, features, recovered, [caption_line(s) for s in lines]))
        rows = int(features.shape[0])
        records.append({**base, "id": cid, "mirror_of": parent, "frames": rows,
                        "seconds": round(rows / FPS, 3), "captions": lines})
    return records, pending


def write_clip(out: Path, clip_id: str, features: np.ndarray, joints: np.ndarray, lines: list[str]) -> None:
    """Write one clip's three files (atomically each)."""
    write_npy(out / "new_joint_vecs" / f"{clip_id}.npy", features)
    write_npy(out / "new_joints" / f"{clip_id}.npy", joints)
    write_text(out / "texts" / f"{clip_id}.txt", "".join(f"{line}\n" for line in lines))


def load_record(path: Path) -> dict[str, Any] | None:
    """A cached JSON record, or None when missing or unreadable."""
    try:
        return json.loads(path.read_text())
    except (OSError, ValueError):
        return None


def files_exist(out: Path, clips: list[dict[str, Any]]) -> bool:
    """Whether the three files of every clip record are in ``out``."""
    return all((out / sub / f"{c['id']}{ext}").is_file() for c in clips for sub, ext in CLIP_FILES)


def remove_stale(out: Path, keep: set[str], candidates: set[str]) -> int:
    """Delete clip files once written by this tool (previous manifest or item records) but not produced now."""
    old = load_record(out / "manifest.json")
    candidates = candidates | {str(c.get("id", "")) for c in (old or {}).get("clips", [])}
    removed = 0
    for cid in sorted(candidates):
        if cid and cid not in keep and "/" not in cid and ".." not in cid:
            for sub, ext in CLIP_FILES:
                path = out / sub / f"{cid}{ext}"
                if path.is_file():
                    path.unlink()
                    removed += 1
    return removed


def write_splits(out: Path, clips: list[dict[str, Any]], split_of: dict[str, str]) -> dict[str, list[str]]:
    """Set each clip's ``split`` from its trial, write ``train/val/test/train_val/all.txt``;
    returns the sorted clip ids per split."""
    ids: dict[str, list[str]] = {name: [] for name in SPLIT_NAMES}
    for clip in clips:
        clip["split"] = split_of[clip["trial"]]
        ids[clip["split"]].append(clip["id"])
    for name in SPLIT_NAMES:
        ids[name].sort()
        write_lines(out / f"{name}.txt", ids[name])
    write_lines(out / "train_val.txt", sorted(ids["train"] + ids["val"]))
    write_lines(out / "all.txt", sorted(c["id"] for c in clips))
    return ids


def write_stats(out: Path, train_ids: list[str]) -> None:
    """Mean.npy / Std.npy with HumanML3D's grouped std over the train clips."""
    from simdiff.motion.normalize import group_std

    if not train_ids:
        raise SimdiffError(f"no train clips in {out}: cannot compute Mean/Std")
    mean, std = group_std(np.load(out / "new_joint_vecs" / f"{cid}.npy") for cid in train_ids)
    std = np.where(std < 1e-6, 1e-6, std).astype(np.float32)  # a constant group (e.g. no contact) must not divide by 0
    write_npy(out / "Mean.npy", mean.astype(np.float32))
    write_npy(out / "Std.npy", std)
