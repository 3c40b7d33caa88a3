"""Where a result came from: the command, the git commit, the machine and the time (for report headers)."""

from __future__ import annotations

import datetime as dt
import os
import platform
import subprocess
import sys
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]


def now() -> str:
    """UTC time, ISO format, seconds."""
    return dt.datetime.now(dt.timezone.utc).isoformat(timespec="seconds")


def _git(*args: str) -> str | None:
    try:
        return subprocess.run(["git", *args], cwd=ROOT, capture_output=True, text=True, timeout=10,
                              check=True).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return None


def run_info(command: list[str] | None = None) -> dict[str, Any]:
    """Command line, git commit (and whether tracked files outside ``reports/`` differ from it), machine, start time."""
    status = _git("status", "--porcelain", "--untracked-files=no", "--", ".", ":!reports")  # reports: the outputs
    return {"command": " ".join(command if command is not None else ["simdiff", *sys.argv[1:]]),
            "git_commit": _git("rev-parse", "HEAD"), "git_dirty": None if status is None else bool(status),
            "machine": {"host": platform.node(), "platform": platform.platform(), "python": platform.python_version(),
                        "cpus": os.cpu_count()},
            "started": now()}


def header_lines(info: dict[str, Any]) -> list[str]:
    """Markdown bullets: command, commit, machine, date."""
    m = info["machine"]
    dirty = " (with uncommitted changes)" if info.get("git_dirty") else ""
    return [f"* command: `{info['command']}`", f"* git commit: {info['git_commit']}{dirty}",
            f"* machine: {m['host']}, {m['platform']}, {m['cpus']} CPUs, Python {m['python']}",
            f"* date: {info['started']}"]
