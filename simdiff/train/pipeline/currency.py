"""The stage-currency rule: a stage is current when its done-marker holds the hash it would get now.

A stage's key hashes its name, its settings and its upstream stages' keys (and, for inputs
read from outside the run, a digest of those files), so a changed setting makes that stage
and everything downstream stale, and nothing upstream.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path
from typing import Any

from simdiff.errors import SimdiffError
from simdiff.fsio import write_json

MARKER_DIR = "stages"
SMALL_FILES = ("Mean.npy", "Std.npy", "train.txt", "val.txt", "test.txt", "all.txt", "train_val.txt", "env.json",
               "conditions.json", "manifest.json", "pack.json")


def digest(value: Any) -> str:
    """sha256 of ``value``'s canonical JSON (sorted keys)."""
    return hashlib.sha256(json.dumps(value, sort_keys=True, default=str).encode("utf-8")).hexdigest()


def folder_digest(folder: str | Path) -> str:
    """A digest of a corpus folder: its small index files' bytes and its feature files' names and sizes."""
    folder = Path(folder)
    if not folder.is_dir():
        raise SimdiffError(f"{folder}: no such corpus folder")
    h = hashlib.sha256()
    for name in SMALL_FILES:
        path = folder / name
        if path.is_file():
            h.update(name.encode() + b"\0" + hashlib.sha256(path.read_bytes()).digest())
    for sub in ("new_joint_vecs", "texts", "arrays"):
        d = folder / sub
        if d.is_dir():
            for path in sorted(d.iterdir()):
                h.update(f"{sub}/{path.name}:{path.stat().st_size}\n".encode())
    return h.hexdigest()


def marker_path(out: Path, stage: str, started: bool = False) -> Path:
    return out / MARKER_DIR / (f"{stage}.started.json" if started else f"{stage}.json")


def read_marker(out: Path, stage: str, started: bool = False) -> dict[str, Any] | None:
    """The stage's done (or started) marker, or None when absent or unreadable."""
    path = marker_path(out, stage, started)
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return data if isinstance(data, dict) else None


def write_marker(out: Path, stage: str, data: dict[str, Any], started: bool = False) -> None:
    write_json(marker_path(out, stage, started), data)


def clear_marker(out: Path, stage: str) -> None:
    for started in (False, True):
        marker_path(out, stage, started).unlink(missing_ok=True)
