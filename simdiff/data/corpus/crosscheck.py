"""Agreement between the kept copy of a trial and its other copies (dedupe cross-check).

Both copies are retargeted at 120 fps (so they can be synced to 1/120 s), run through the
corpus joint stage (canonical skeleton, floor, facing +Z: :func:`simdiff.motion.features.process_joints`)
and compared by :func:`simdiff.data.corpus.joint_agreement.compare_joints` (best lag within ±0.2 s,
then yaw + 3D translation). Results are cached in ``CORPUS/.build/crosscheck_all.json`` by the
bytes of both files.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from simdiff.data.corpus.joint_agreement import CHECK_FPS
from simdiff.data.writer import write_json
from simdiff.data.corpus.item import Item
from simdiff.errors import SimdiffError
from simdiff.fsio import file_digest

VERSION: int = 2
"""Bump when the comparison changes (invalidates the cache)."""
TARGET_M: float = 0.03
"""Wanted mean per-joint distance between two copies after alignment (metres)."""


def _joints_120(item: Item) -> np.ndarray:
    """(T, 22, 3) canonical joints of ``item`` at :data:`CHECK_FPS`."""
    from simdiff.data.corpus.cmu_load import read_source_rig
    from simdiff.motion.features import process_joints
    from simdiff.motion.io import load_rig, retarget_rig

    rigs = {"cmu-amc": "amc", "cmu-bvh": "bvh", "cmu-deepmimic": "deepmimic"}
    if item.source in rigs and "cmu_trial" in item.meta:
        rig = read_source_rig(item.meta["cmu_trial"], rigs[item.source])[0]  # type: ignore[arg-type]
    else:
        rig = load_rig(item.path, asf=item.asf, fps=item.fps)
    return process_joints(retarget_rig(rig, fps=CHECK_FPS)).joints.astype(np.float64)


def crosscheck_items(items: list[Item], cache_path: Path, progress: bool = True) -> list[dict[str, Any]]:
    """One row per (kept item, alternate copy): trial, sources, frames, lag, MPJPE and pose-only (m)."""
    from tqdm import tqdm

    from simdiff.data.corpus.joint_agreement import compare_joints

    try:
        cache = json.loads(cache_path.read_text())
    except (OSError, ValueError):
        cache = {}
    pairs = [(item, alt) for item in items for alt in item.alternates]
    rows: list[dict[str, Any]] = []
    for item, alt in tqdm(pairs, desc="cross-check", unit="pair", disable=not progress, leave=False):
        name = f"{item.id}:{item.source}:{alt.source}"
        key = file_digest(item.files() + alt.files()) + f":v{VERSION}"
        entry = cache.get(name)
        if not (entry and entry.get("key") == key):
            try:
                agreement = compare_joints(_joints_120(item), _joints_120(alt), CHECK_FPS, trial=item.id)
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
