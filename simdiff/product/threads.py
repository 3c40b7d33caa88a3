"""How many CPU threads ``simdiff generate`` gives torch by default.

torch uses one thread per core. On a machine whose cores are busy with other work, its
threads wait on each other: measured on 2 cores with one taken by another job, DDIM-50 for a
6-s motion with the ``small`` model took 7.2 s on 2 threads and 1.15 s on 1. So the default
is the number of idle cores (from the 1-minute load average), at least 1 and at most torch's own.
"""

from __future__ import annotations

import os


def idle_cores(cpus: int | None = None, load: float | None = None) -> int:
    """Cores not busy with other work: ``round(cpus - load)``, at least 1.

    Args:
        cpus: logical CPUs available (default: ``os.cpu_count()``).
        load: 1-minute load average (default: ``os.getloadavg()``; 0 where unsupported).
    """
    if cpus is None:
        cpus = os.cpu_count() or 1
    if load is None:
        try:
            load = os.getloadavg()[0]
        except (AttributeError, OSError):  # Windows
            load = 0.0
    return max(1, int(round(cpus - load)))


def default_threads(torch_default: int, cpus: int | None = None, load: float | None = None) -> int:
    """torch intra-op threads to use: the idle cores, capped by ``torch_default`` (torch's own choice)."""
    return max(1, min(int(torch_default), idle_cores(cpus, load)))
