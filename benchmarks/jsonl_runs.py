"""Resumable benchmark runs that append one JSON record per task to a ``.jsonl`` file.

Shared by ``bench_flight.py`` and ``bench_augment_sample.py``: finished tasks are read back
and skipped, records are appended and flushed as they come (a killed run loses at most the
tasks in flight), and ``--summary FILE`` writes ``FILE.summary.json`` from a finished run.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Hashable, Iterable
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any


def write_summary(path: Path, summary: Callable[[Path], dict[str, Any]]) -> int:
    """Write ``summary(path)`` beside ``path`` as ``.summary.json``, print it; returns 0."""
    s = summary(path)
    path.with_suffix(".summary.json").write_text(json.dumps(s, indent=1))
    print(json.dumps(s, indent=1))
    return 0


def done_keys(out: Path, key: Callable[[dict[str, Any]], Hashable]) -> set[Hashable]:
    """Keys of the records already in ``out`` (empty when it does not exist)."""
    done: set[Hashable] = set()
    if out.exists():
        for line in out.read_text().splitlines():
            if line.strip():
                done.add(key(json.loads(line)))
    return done


def run_appending(tasks: Iterable[Any], run_task: Callable[[Any], dict[str, Any]], out: Path, workers: int,
                  show: Callable[[dict[str, Any]], str]) -> None:
    """Run ``tasks`` in ``workers`` processes (in order), appending each record to ``out`` and printing ``show(record)``."""
    out.parent.mkdir(parents=True, exist_ok=True)
    with ProcessPoolExecutor(workers) as ex, out.open("a") as f:
        for rec in ex.map(run_task, list(tasks), chunksize=1):
            f.write(json.dumps(rec) + "\n")
            f.flush()
            print(show(rec), flush=True)
