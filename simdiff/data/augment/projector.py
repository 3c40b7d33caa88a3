"""How the augmentation runs the simulator: a persistent local process pool, Ray, or serial.

A *projector* is any callable ``(motions, envs) -> iterable of (rollout | None, info)``
yielding results in input order (``info`` a :class:`ProjectionInfo`, its dict, or an error
string). :func:`make_projector` builds the default one on :func:`simdiff.sim.project`;
tests inject fakes.
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Iterator, Sequence
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from simdiff.errors import SimdiffError
from simdiff.sim.env import Environment

Result = tuple[np.ndarray | None, Any]
Projector = Callable[[Sequence[np.ndarray], Sequence[Environment]], Iterable[Result]]

_NORMALIZERS: dict[str, Any] = {}


def _project_task(task: tuple[np.ndarray, tuple[float, float, float], str | None, float]) -> Result:
    """Worker: project one motion; exceptions become an error string (one bad clip never stops a run)."""
    joints, phi, stats_dir, max_force = task
    try:
        from simdiff.motion.normalize import Normalizer
        from simdiff.sim.project import project
        from simdiff.sim.residual import ResidualConfig

        normalizer = None
        if stats_dir is not None:
            if stats_dir not in _NORMALIZERS:
                _NORMALIZERS[stats_dir] = Normalizer.from_dir(stats_dir)
            normalizer = _NORMALIZERS[stats_dir]
        return project(joints, Environment(*phi), residual=ResidualConfig(max_force=max_force), normalizer=normalizer)
    except Exception as exc:  # noqa: BLE001 - reported per pair
        return None, f"{type(exc).__name__}: {exc}"


def _init_worker() -> None:
    os.environ["OMP_NUM_THREADS"] = "1"


@dataclass
class SimProjector:
    """The default projector.

    Args:
        stats_dir: folder with Mean.npy/Std.npy for d_L2 (the source corpus).
        workers: processes (``process``) or concurrent tasks (``ray``); 0 = all cores.
        backend: ``process`` (a pool kept alive across shards), ``ray`` or ``serial``.
        max_force: root residual bound (fraction of m·|g_z|) passed to the tracker.
    """

    stats_dir: str | None
    workers: int = 0
    backend: str = "process"
    max_force: float = 0.5

    def __post_init__(self) -> None:
        if self.backend not in ("process", "ray", "serial"):
            raise SimdiffError(f"unknown backend {self.backend!r}; choose process, ray or serial")
        self._executor: ProcessPoolExecutor | None = None

    def __call__(self, motions: Sequence[np.ndarray], envs: Sequence[Environment]) -> Iterator[Result]:
        tasks = [(np.asarray(m, dtype=np.float32), e.as_tuple(), self.stats_dir, self.max_force) for m, e in zip(motions, envs)]
        workers = self.workers or os.cpu_count() or 1
        if self.backend == "serial" or (self.backend == "process" and workers == 1):
            return (_project_task(t) for t in tasks)
        if self.backend == "ray":
            from simdiff.sim.pool import PoolConfig, ProjectionPool
            from simdiff.sim.residual import ResidualConfig

            pool = ProjectionPool(PoolConfig(workers=workers, backend="ray", residual=ResidualConfig(max_force=self.max_force),
                                             stats_dir=self.stats_dir))
            return iter(pool.map(list(motions), list(envs)))
        if self._executor is None:
            import multiprocessing as mp

            self._executor = ProcessPoolExecutor(max_workers=workers, mp_context=mp.get_context("spawn"),
                                                 initializer=_init_worker)
        return self._executor.map(_project_task, tasks, chunksize=1)

    def close(self) -> None:
        """Shut the worker processes down."""
        if self._executor is not None:
            self._executor.shutdown(wait=True, cancel_futures=True)
            self._executor = None
