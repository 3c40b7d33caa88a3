"""Find a source folder either unpacked under the shared root or inside its ``.tar.xz``
(extracted once into the build cache, keyed by the archive's size and mtime)."""

from __future__ import annotations

import tarfile
from pathlib import Path

from simdiff.errors import SimdiffError


def source_dir(shared: Path, cache: Path, name: str) -> Path | None:
    """``shared/extra/<name>/`` if unpacked, else ``cache/extract/<name>/`` from
    ``shared/extra/<name>.tar.xz``; None when neither exists.

    Raises:
        SimdiffError: the archive cannot be read.
    """
    folder = shared / "extra" / name
    if folder.is_dir():
        return folder
    archive = shared / "extra" / f"{name}.tar.xz"
    if not archive.is_file():
        return None
    root = cache / "extract"
    target = root / name
    stamp = root / f".{name}.extracted"
    stat = archive.stat()
    key = f"{stat.st_size}:{stat.st_mtime_ns}"
    if not (stamp.is_file() and stamp.read_text() == key and target.is_dir()):
        root.mkdir(parents=True, exist_ok=True)
        try:
            with tarfile.open(archive, "r:xz") as tar:
                members = [m for m in tar.getmembers() if m.isfile() or m.isdir()]
                bad = [m.name for m in members if m.name.startswith("/") or ".." in Path(m.name).parts]
                if bad:
                    raise SimdiffError(f"{archive}: unsafe member path {bad[0]!r}")
                tar.extractall(root, members=members, filter="data")
        except (tarfile.TarError, OSError, EOFError) as exc:
            raise SimdiffError(f"cannot read {archive}: {exc}") from None
        stamp.write_text(key)
    return target if target.is_dir() else None
