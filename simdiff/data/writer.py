"""Atomic file writes for the corpus (write a temporary file, then ``os.replace``)."""

from __future__ import annotations

import io
import json
import os
from pathlib import Path
from typing import Any

import numpy as np


def write_bytes(path: Path, data: bytes) -> None:
    """Write ``data`` to ``path`` atomically (unchanged files are not rewritten)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    if path.is_file():
        try:
            if path.stat().st_size == len(data) and path.read_bytes() == data:
                return
        except OSError:
            pass
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    with open(tmp, "wb") as handle:
        handle.write(data)
    os.replace(tmp, path)


def write_text(path: Path, text: str) -> None:
    """Write UTF-8 text atomically."""
    write_bytes(path, text.encode("utf-8"))


def write_json(path: Path, value: Any) -> None:
    """Write JSON (sorted keys, 1-space indent) atomically."""
    write_text(path, json.dumps(value, indent=1, sort_keys=True) + "\n")


def write_npy(path: Path, array: np.ndarray) -> None:
    """Save an array as ``.npy`` atomically."""
    buffer = io.BytesIO()
    np.save(buffer, np.ascontiguousarray(array), allow_pickle=False)
    write_bytes(path, buffer.getvalue())


def write_lines(path: Path, lines: list[str]) -> None:
    """Write lines (each followed by a newline) atomically."""
    write_text(path, "".join(f"{line}\n" for line in lines))
