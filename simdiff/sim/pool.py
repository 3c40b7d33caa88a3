"""Project many motions in parallel: local processes by default, Ray for a cluster.

Each task is one ``(joints, env)`` pair; the result is ``(rollout_joints, ProjectionInfo)``
in input order. A task that raises (bad input, MuJoCo error) yields ``(None, error string)``
instead of stopping the batch. The local process pool is kept alive across calls (close it
with :meth:`ProjectionPool.close` or use the pool as a context manager); each worker caps
its BLAS / OpenMP / torch threads to one (:func:`limit_threads`) before its first task.

A *projector* (:data:`Projector`) is any callable ``(motions, envs) -> iterable of
(rollout | None, info)`` in input order; a :class:`ProjectionPool`'s :meth:`~ProjectionPool.imap`
is one, the augmentation and the PhysDiff baseline take any (tests inject fakes).
"""

from __future__ import annotations

import functools
import os
import sys
from collections.abc import Callable, Iterable, Iterator, Sequence
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from simdiff.errors import SimdiffError
from simdiff.sim.retarget.config import RetargetConfig
from simdiff.sim.env import Environment
from simdiff.sim.fallback import FallbackConfig
from simdiff.sim.flight import FlightConfig
from simdiff.sim.project import ProjectionInfo, project
from simdiff.sim.residual import ResidualConfig
from simdiff.sim.retime import RetimeConfig
from simdiff.sim.tracker import PDTrackerConfig


@dataclass(frozen=True)
class PoolConfig:
    """Options shared by every task of a pool.

    Attributes:
        workers: processes (``process``) or concurrent tasks (``ray``); 0 = os.cpu_count().
        backend: ``"process"`` (local, default), ``"ray"`` (cluster) or ``"serial"``.
        residual, retarget: passed to :func:`project`.
        stats_dir: folder with Mean.npy/Std.npy for d_L2 (None: d_L2 is NaN).
        force: skip φ range validation.
        ray_address: address for ``ray.init`` (None: local or RAY_ADDRESS).
        flight: the flight clock passed to :func:`project` (None: the reference's own clock).
        retime: the weak-gravity second try passed to :func:`project` (None: one try).
        tracker_config: the default tracker's settings passed to :func:`project` (None: its defaults).
        fallback: the second try with other tracker settings passed to :func:`project` (None: none).
    """

    workers: int = 0
    backend: str = "process"
    residual: ResidualConfig = ResidualConfig()
    retarget: RetargetConfig = RetargetConfig()
    stats_dir: str | None = None
    force: bool = False
    ray_address: str | None = None
    extra: dict = field(default_factory=dict)
    flight: FlightConfig | None = None
    retime: RetimeConfig | None = None
    tracker_config: PDTrackerConfig | None = None
    fallback: FallbackConfig | None = None


Result = tuple[np.ndarray | None, Any]
Projector = Callable[[Sequence[np.ndarray], Sequence[Environment]], Iterable[Result]]

_THREAD_VARS = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")
_NORMALIZER_CACHE: dict[str, object] = {}


def limit_threads(n: int = 1) -> None:
    """Cap this process's BLAS / OpenMP thread pools and torch's intra-op threads to ``n``.

    Setting ``OMP_NUM_THREADS`` only works before numpy or torch load their thread pools, and a
    worker has imported numpy by the time its initializer runs; so the already loaded pools are
    resized through threadpoolctl (and ``torch.set_num_threads`` when torch is loaded), and the
    variables are set too for libraries loaded later.
    """
    from threadpoolctl import threadpool_limits

    for var in _THREAD_VARS:
        os.environ[var] = str(n)
    threadpool_limits(limits=n)
    if "torch" in sys.modules:
        sys.modules["torch"].set_num_threads(n)


def exit_with_parent(parent: int, period_s: float = 1.0) -> None:
    """In a worker process: end it (exit status 1) once ``parent`` (its creator's pid) is gone.

    A command killed without running its cleanup (SIGTERM from a scheduler, SIGKILL, a crashed
    parent) would otherwise leave its pool's workers simulating as orphans; a daemon thread checks
    ``os.getppid()`` every ``period_s`` seconds (a re-parented orphan sees another pid).
    """
    import threading
    import time

    def watch() -> None:
        while os.getppid() == parent:
            time.sleep(period_s)
        os._exit(1)

    threading.Thread(target=watch, name="exit-with-parent", daemon=True).start()


def worker_init(threads: int, parent: int) -> None:
    """Pool initializer: :func:`limit_threads` and :func:`exit_with_parent`. Pass ``(n, os.getpid())``."""
    limit_threads(threads)
    exit_with_parent(parent)


@functools.lru_cache(maxsize=1)
def _single_threaded_worker() -> None:
    """:func:`limit_threads` once per worker process (Ray workers have no initializer)."""
    limit_threads(1)


def _normalizer(stats_dir: str | None):
    if stats_dir is None:
        return None
    if stats_dir not in _NORMALIZER_CACHE:
        from simdiff.motion.normalize import Normalizer

        _NORMALIZER_CACHE[stats_dir] = Normalizer.from_dir(stats_dir)
    return _NORMALIZER_CACHE[stats_dir]


def _run_one(args: tuple[np.ndarray, tuple[float, float, float], PoolConfig]) -> tuple[np.ndarray | None, ProjectionInfo | str]:
    joints, phi, cfg = args
    try:
        return project(
            joints, Environment(*phi), residual=cfg.residual, retarget=cfg.retarget,
            normalizer=_normalizer(cfg.stats_dir), force=cfg.force, flight=cfg.flight, retime=cfg.retime,
            tracker_config=cfg.tracker_config, fallback=cfg.fallback,
        )
    except Exception as exc:  # one bad motion must not stop the batch
        return None, f"{type(exc).__name__}: {exc}"


def _run_one_pooled(args: tuple[np.ndarray, tuple[float, float, float], PoolConfig]) -> Result:
    """:func:`_run_one` in a pool worker: single-threaded BLAS / OpenMP / torch first."""
    _single_threaded_worker()
    return _run_one(args)


class ProjectionPool:
    """Run :func:`project` over many motions.

    Example:
        >>> with ProjectionPool(PoolConfig(workers=2)) as pool:
        ...     results = pool.map([joints_a, joints_b], [Environment(), Environment(-3.0)])
    """

    def __init__(self, config: PoolConfig = PoolConfig()) -> None:
        if config.backend not in ("process", "ray", "serial"):
            raise SimdiffError(f"unknown pool backend {config.backend!r} (process, ray, serial)")
        self.cfg = config
        self._executor: ProcessPoolExecutor | None = None

    def __enter__(self) -> "ProjectionPool":
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def __call__(self, motions: Sequence[np.ndarray], envs: Sequence[Environment]) -> Iterator[Result]:
        """:meth:`imap`: a pool is a :data:`Projector`."""
        return self.imap(motions, envs)

    def map(
        self, motions: Sequence[np.ndarray], envs: Iterable[Environment] | Environment = Environment(),
        progress: Callable[[Iterable], Iterable] | None = None,
    ) -> list[tuple[np.ndarray | None, ProjectionInfo | str]]:
        """Project every motion under its environment (one env for all, or one per motion).

        Every environment is validated first (``SimdiffError`` names a bad one). ``progress``
        wraps the in-order result iterator (e.g. ``tqdm``).
        """
        envs_list = [envs] * len(motions) if isinstance(envs, Environment) else list(envs)
        if len(envs_list) != len(motions):
            raise SimdiffError(f"{len(motions)} motions but {len(envs_list)} environments")
        for e in envs_list:
            e.validate(force=self.cfg.force)
        results = self.imap(motions, envs_list)
        return list(progress(results) if progress is not None else results)

    def imap(self, motions: Sequence[np.ndarray], envs: Sequence[Environment]) -> Iterator[Result]:
        """Results in input order as they arrive; a bad environment is that pair's error string."""
        if len(envs) != len(motions):
            raise SimdiffError(f"{len(motions)} motions but {len(envs)} environments")
        tasks = [(np.asarray(m, dtype=np.float32), e.as_tuple(), self.cfg) for m, e in zip(motions, envs)]
        workers = self.cfg.workers or os.cpu_count() or 1
        if self.cfg.backend == "serial" or (self.cfg.backend == "process" and workers == 1):
            return (_run_one(t) for t in tasks)
        if self.cfg.backend == "ray":
            return iter(self._map_ray(tasks, workers))
        if self._executor is None:
            import multiprocessing as mp

            self._executor = ProcessPoolExecutor(max_workers=workers, mp_context=mp.get_context("spawn"),
                                                 initializer=worker_init, initargs=(1, os.getpid()))
        return self._executor.map(_run_one, tasks, chunksize=1)

    def close(self) -> None:
        """Shut the worker processes down (a later call starts new ones)."""
        if self._executor is not None:
            self._executor.shutdown(wait=True, cancel_futures=True)
            self._executor = None

    def _map_ray(self, tasks: list, workers: int) -> list:
        try:
            import ray
        except ImportError as exc:
            raise SimdiffError("the ray backend needs Ray: pip install 'simdiff[cluster]'") from exc
        if not ray.is_initialized():
            ray.init(address=self.cfg.ray_address, ignore_reinit_error=True, log_to_driver=False)
        remote = ray.remote(num_cpus=1)(_run_one_pooled)
        pending = []
        results: list = [None] * len(tasks)
        refs = {}
        for i, t in enumerate(tasks):
            if len(pending) >= workers:
                done, pending = ray.wait(pending, num_returns=1)
                for r in done:
                    results[refs.pop(r)] = ray.get(r)
            ref = remote.remote(t)
            refs[ref] = i
            pending.append(ref)
        for r in pending:
            results[refs.pop(r)] = ray.get(r)
        return results
