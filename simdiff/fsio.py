"""Atomic file output: every writer goes through a temporary file in the target's folder.

A file either appears complete under its final name (``os.replace`` is atomic on one file
system) or not at all: a full disk, a read-only folder or an exception in the writer leaves
nothing half-written behind, and the failure becomes one :class:`SimdiffError` line naming
the path and the reason. The temporary file keeps the target's suffix, so writers that pick
a format from the name (Pillow, matplotlib, ffmpeg) still do.
"""

from __future__ import annotations

import errno
import json
import os
import shutil
import tempfile
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, Any, Iterator, Mapping

import numpy as np

from simdiff.errors import SimdiffError

if TYPE_CHECKING:
    from torch import Tensor

_REASONS: dict[int, str] = {
    errno.ENOSPC: "no space left on device",
    errno.EROFS: "read-only file system",
    errno.EACCES: "permission denied",
    errno.EPERM: "permission denied",
    errno.ENOTDIR: "a parent of it is not a folder",
    errno.EISDIR: "it is a folder",
    errno.EDQUOT: "disk quota exceeded",
    errno.EPIPE: "the encoder stopped (broken pipe)",
}


def reason(exc: BaseException) -> str:
    """A short human reason for an ``OSError`` (``"no space left on device"``) or any exception."""
    if isinstance(exc, OSError):
        if exc.errno in _REASONS:
            return _REASONS[exc.errno]
        if exc.strerror:
            return exc.strerror.lower()
    text = str(exc).strip().splitlines()
    return text[0] if text else type(exc).__name__


def write_error(path: str | Path, exc: BaseException) -> SimdiffError:
    """The one-line error for a failed write of ``path``."""
    return SimdiffError(f"cannot write {str(path)!r}: {reason(exc)}")


def ensure_parent(path: str | Path) -> Path:
    """Create ``path``'s folder (and its parents); one-line :class:`SimdiffError` when impossible."""
    path = Path(path)
    parent = path.parent
    try:
        parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise SimdiffError(f"cannot create folder {str(parent)!r} for {str(path)!r}: {reason(exc)}") from None
    if not parent.is_dir():
        raise SimdiffError(f"cannot write {str(path)!r}: {str(parent)!r} is not a folder")
    return path


def ensure_dir(path: str | Path) -> Path:
    """Create the output folder ``path``; a file in its place or an unwritable parent is one error line."""
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise SimdiffError(f"output folder {str(path)!r} exists and is not a folder")
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise SimdiffError(f"cannot create folder {str(path)!r}: {reason(exc)}") from None
    return path


def _temp_name(path: Path) -> Path:
    return path.with_name(f".{path.stem}.tmp{os.getpid()}{path.suffix}")


def _check_target(path: Path) -> None:
    """A target that exists must be a regular file: renaming onto a device (``/dev/full``), a folder or a pipe
    would replace it."""
    if path.is_dir():
        raise SimdiffError(f"cannot write {str(path)!r}: it is a folder")
    if path.exists() and not path.is_file():
        raise SimdiffError(f"cannot write {str(path)!r}: it is not a regular file")


def check_writable(path: str | Path) -> Path:
    """Fail early (before slow work) when ``path`` cannot be written: creates its folder, probes a temp file."""
    path = ensure_parent(path)
    _check_target(path)
    probe = _temp_name(path)
    try:
        with open(probe, "wb"):
            pass
    except OSError as exc:
        raise write_error(path, exc) from None
    finally:
        try:
            probe.unlink()
        except OSError:
            pass
    return path


@contextmanager
def atomic_path(path: str | Path) -> Iterator[Path]:
    """Yield a temporary path beside ``path`` (same suffix); on success it replaces ``path``.

    On any exception the temporary file is removed and ``path`` is left untouched; an
    ``OSError`` (and a writer's error while writing) becomes one :class:`SimdiffError` line.
    A :class:`SimdiffError` raised by the writer passes through unchanged.
    """
    path = ensure_parent(path)
    _check_target(path)
    tmp = _temp_name(path)
    try:
        yield tmp
        os.replace(tmp, path)
    except BaseException as exc:
        try:
            tmp.unlink()
        except OSError:
            pass
        if isinstance(exc, (SimdiffError, KeyboardInterrupt, SystemExit, GeneratorExit)):
            raise
        if isinstance(exc, OSError):
            raise write_error(path, exc) from None
        raise


@contextmanager
def output_set(folder: str | Path, last: str | None = None) -> Iterator[Path]:
    """Write several files as one set: yield a hidden staging folder inside ``folder``.

    When the block succeeds every file written in the staging folder is renamed into ``folder``
    (``last``, e.g. the index ``generation.json``, after all the others, so its presence means the
    set is complete); on any exception, Ctrl-C included, the staging folder is removed and
    ``folder`` gains nothing. Renames need no space, so a full disk fails before the first one.
    """
    folder = ensure_dir(folder)
    try:
        stage = Path(tempfile.mkdtemp(prefix=".simdiff-partial-", dir=folder))
    except OSError as exc:
        raise write_error(folder, exc) from None
    try:
        try:
            yield stage
        except SimdiffError as exc:  # name the final file, not its staged copy
            raise SimdiffError(str(exc).replace(str(stage), str(folder))) from None
        names = sorted(p.name for p in stage.iterdir())
        if last in names:
            names.remove(last)
            names.append(last)
        for name in names:
            os.replace(stage / name, folder / name)
    finally:
        shutil.rmtree(stage, ignore_errors=True)


def write_bytes(path: str | Path, data: bytes) -> Path:
    """Write ``data`` to ``path`` atomically."""
    with atomic_path(path) as tmp:
        with open(tmp, "wb") as handle:
            handle.write(data)
            handle.flush()
            os.fsync(handle.fileno())
    return Path(path)


def write_text(path: str | Path, text: str) -> Path:
    """Write UTF-8 ``text`` to ``path`` atomically."""
    return write_bytes(path, text.encode("utf-8"))


def write_json(path: str | Path, data: Any, indent: int | None = 2, allow_nan: bool = True) -> Path:
    """Write ``data`` as JSON (with a final newline) atomically; ``allow_nan=False`` refuses NaN/inf."""
    try:
        text = json.dumps(data, indent=indent, allow_nan=allow_nan)
    except ValueError as exc:
        raise SimdiffError(f"cannot write {str(path)!r}: {exc}") from None
    return write_text(path, text + "\n")


def read_json(path: str | Path) -> Any:
    """Parse a JSON file; an unreadable or malformed file is one :class:`SimdiffError` line naming it."""
    try:
        return json.loads(Path(path).read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, ValueError) as exc:
        first = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise SimdiffError(f"{path}: cannot read JSON: {first}") from None


def read_config_json(path: Path) -> Any:
    """Parse a configuration file; undecodable, malformed or unreadable is one line naming it and the line."""
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except UnicodeDecodeError:
        raise SimdiffError(f"{path}: not a UTF-8 text file") from None
    except json.JSONDecodeError as exc:
        raise SimdiffError(f"{path}: invalid JSON ({exc.msg}, line {exc.lineno})") from None
    except OSError as exc:
        raise SimdiffError(f"{path}: cannot read ({exc.strerror or exc})") from None


def save_npy(path: str | Path, array: np.ndarray) -> Path:
    """Save ``array`` as ``.npy`` at exactly ``path`` (no suffix added) atomically."""
    with atomic_path(path) as tmp:
        with open(tmp, "wb") as handle:
            np.save(handle, np.asarray(array))
            handle.flush()
            os.fsync(handle.fileno())
    return Path(path)


def file_digest(paths: list[Path]) -> str:
    """SHA-1 (hex) of the concatenated bytes of ``paths``, read in 1 MiB blocks."""
    import hashlib

    sha = hashlib.sha1()
    for path in paths:
        with open(path, "rb") as handle:
            for block in iter(lambda: handle.read(1 << 20), b""):
                sha.update(block)
    return sha.hexdigest()


def canonical_safetensors(blob: bytes) -> bytes:
    """``blob`` (a serialised safetensors file) with its ``__metadata__`` keys sorted: the library writes that map in
    a per-process random order, so the same weights hashed differently from run to run. Tensor entries and data are
    untouched; the header keeps its length (it is the same JSON reordered)."""
    n = int.from_bytes(blob[:8], "little")
    header = json.loads(blob[8:8 + n])
    meta = header.get("__metadata__")
    if not meta:
        return blob
    header["__metadata__"] = dict(sorted(meta.items()))
    text = json.dumps(header, separators=(",", ":"), ensure_ascii=False).encode("utf-8")
    if len(text) > n:  # never: the same keys and values, reordered (kept safe: then the library's bytes stand)
        return blob
    return blob[:8] + text + b" " * (n - len(text)) + blob[8 + n:]


def atomic_save_tensors(tensors: Mapping[str, Tensor], path: str | os.PathLike[str],
                        metadata: dict[str, str] | None = None) -> None:
    """Write a safetensors file atomically (tensors made contiguous, on CPU); the same tensors and metadata give the
    same bytes (:func:`canonical_safetensors`). torch is imported here, so that this module stays light."""
    from safetensors.torch import save

    clean = {k: v.detach().to("cpu").contiguous() for k, v in tensors.items()}
    write_bytes(path, canonical_safetensors(save(clean, metadata=metadata)))
