"""Feedback for small commands: a note on stderr when a step takes longer than a second."""

from __future__ import annotations

import sys
import threading
from contextlib import contextmanager
from typing import Iterator, TextIO

NOTICE_AFTER_S: float = 1.0
"""Seconds a step may take silently."""


@contextmanager
def slow_notice(message: str, after: float = NOTICE_AFTER_S, stream: TextIO | None = None) -> Iterator[None]:
    """Print ``simdiff: <message> …`` to stderr if the block is still running after ``after`` seconds."""
    out = stream if stream is not None else sys.stderr

    def say() -> None:
        print(f"simdiff: {message} …", file=out, flush=True)

    timer = threading.Timer(after, say)
    timer.daemon = True
    timer.start()
    try:
        yield
    finally:
        timer.cancel()
