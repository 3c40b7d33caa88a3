"""Agreement between the kept copy of a trial and its other copies (dedupe cross-check).

Both copies are read as corpus items (:func:`.load.load_item`, 20 fps, floor at 0) and
compared by :func:`simdiff.data.cmu.crosscheck.compare_joints` (best lag within ±0.2 s, then
yaw + 3D translation). Results are cached in ``CORPUS/.build/crosscheck_all.json`` by the
bytes of both files.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from simdiff.data.cmu.writer import write_json
from simdiff.data.corpus.item import Item, file_digest
from simdiff.errors import SimdiffError
from simdiff.motion.skeleton import FPS

TARGET_M: float = 0.03
"""Wanted mean per-joint distance between two copies after alignment (metres)."""


def crosscheck_items(items: list[Item], cache_path: Path, progress: bool = True) -> list[dict[str, Any]]:
    """One row per (kept item, alternate copy): trial, sources, frames, lag, MPJPE and pose-only (m)."""
    from tqdm import tqdm

    from simdiff.data.cmu.crosscheck import compare_joints
    from simdiff.data.corpus.load import load_item

    try:
        cache = json.loads(cache_path.read_text())
    except (OSError, ValueError):
        cache = {}
    pairs = [(item, alt) for item in items for alt in item.alternates]
    rows: list[dict[str, Any]] = []
    for item, alt in tqdm(pairs, desc="cross-check", unit="pair", disable=not progress, leave=False):
        name = f"{item.id}:{item.source}:{alt.source}"
        key = file_digest(item.files() + alt.files())
        entry = cache.get(name)
        if not (entry and entry.get("key") == key):
            try:
                a, b = load_item(item)[0], load_item(alt)[0]
                agreement = compare_joints(a, b, FPS, trial=item.id)
                entry = {"key": key, "row": {
                    "trial": item.id, "kept": item.source, "copy": alt.source, "frames": agreement.frames,
                    "lag_s": agreement.lag_s, "mpjpe": agreement.mpjpe, "pose_only": agreement.root_relative,
                    "worst_joint": agreement.worst_joint, "error": None}}
            except (SimdiffError, ValueError) as exc:
                entry = {"key": key, "row": {"trial": item.id, "kept": item.source, "copy": alt.source,
                                             "error": str(exc).splitlines()[0]}}
            cache[name] = entry
        rows.append(entry["row"])
    write_json(cache_path, cache)
    return rows
