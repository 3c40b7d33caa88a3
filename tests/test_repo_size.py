"""The tracked tree leaves room for a lent GPU machine's call: everything that travels there (tracked files, untracked
files git does not ignore, and the carried packs, text table and wheels) counts against its 64 MiB (measured: at
90.7 MB tracked, every device call was refused before a machine started)."""

from __future__ import annotations

import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
LIMIT_MIB = 48
"""At most this many MiB tracked, so a device call can carry at least 16 MiB (docs/training_pipeline.md)."""


def tracked_bytes(root: Path) -> int | None:
    """Bytes of the files git tracks under ``root`` as they are on disk; None outside a git checkout."""
    try:
        out = subprocess.run(["git", "ls-files", "-z"], cwd=root, capture_output=True, check=True).stdout
    except (OSError, subprocess.CalledProcessError):
        return None
    files = [root / p for p in out.decode("utf-8", "surrogateescape").split("\0") if p]
    return sum(f.stat().st_size for f in files if f.is_file()) if files else None


def test_tracked_tree_leaves_room_for_a_device_call() -> None:
    size = tracked_bytes(ROOT)
    if size is None:
        pytest.skip("not a git checkout")
    assert size <= LIMIT_MIB * 2**20, (
        f"tracked files take {size / 2**20:.1f} MiB, over {LIMIT_MIB} MiB: a GPU call could carry under 16 MiB; "
        "keep large artefacts out of the tree")


def test_tracked_bytes_counts_files(tmp_path: Path) -> None:
    assert tracked_bytes(tmp_path) is None  # not a checkout
    subprocess.run(["git", "init", "-q"], cwd=tmp_path, check=True)
    (tmp_path / "a.bin").write_bytes(b"x" * 1000)
    (tmp_path / "b.txt").write_text("untracked")
    subprocess.run(["git", "add", "a.bin"], cwd=tmp_path, check=True)
    assert tracked_bytes(tmp_path) == 1000
