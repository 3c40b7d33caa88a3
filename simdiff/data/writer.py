"""Atomic file writes for the corpus (write a temporary file, then ``os.replace``), the check that an output folder
is apart from its source, and the clean-up of the folders a failed command created."""

from __future__ import annotations

import io
import json
import os
import shutil
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np

from simdiff.errors import SimdiffError


def check_apart(source: str | os.PathLike[str], out: str | os.PathLike[str], source_flag: str, out_flag: str) -> None:
    """Refuse an output folder ``out`` that is, lies inside, or contains the input folder ``source`` (links and
    ``..`` resolved): writing there would overwrite or mix with the input.

    Raises:
        SimdiffError: one line naming both options and folders.
    """
    src, dst = Path(source).resolve(), Path(out).resolve()
    if src == dst:
        relation = "is"
    elif src in dst.parents:
        relation = "lies inside"
    elif dst in src.parents:
        relation = "contains"
    else:
        return
    raise SimdiffError(f"{out_flag} {str(out)!r} {relation} {source_flag} {str(source)!r}: "
                       f"write the output to a folder apart from the input")


def _first_missing(folder: Path) -> Path | None:
    """The outermost of ``folder`` and its parents that does not exist yet (None when ``folder`` exists)."""
    missing = None
    for path in (folder, *folder.parents):
        if path.exists():
            break
        missing = path
    return missing


@contextmanager
def cleaned_on_failure(folder: str | os.PathLike[str], keep: Callable[[], bool] = lambda: False) -> Iterator[Path]:
    """Create ``folder`` (and its parents); when the block raises and ``keep()`` is false (no work worth resuming
    was done), remove the folders this call created, so that a failed command leaves nothing behind."""
    folder = Path(folder)
    created = _first_missing(folder)
    if folder.exists() and not folder.is_dir():
        raise SimdiffError(f"output folder {str(folder)!r} exists and is not a folder")
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise SimdiffError(f"cannot create folder {str(folder)!r}: {exc.strerror or exc}") from None
    try:
        yield folder
    except BaseException:
        if created is not None and not keep():
            shutil.rmtree(created, ignore_errors=True)
        raise


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
