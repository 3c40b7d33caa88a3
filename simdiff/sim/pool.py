"""Project many motions in parallel: local processes by default, Ray for a cluster.

Each task is one ``(joints, env)`` pair; the result is ``(rollout_joints, ProjectionInfo)``
in input order. A task that raises (bad input, MuJoCo error) yields ``(None, error string)``
instead of stopping the batch. The local process pool is kept alive across calls (close it
with :meth:`ProjectionPool.close` or use the pool as a context manager); each worker caps
its BLAS / OpenMP / torch threads to one (:func:`limit_threads`) before its first task.

Stopping: workers ignore SIGINT (a Ctrl-C reaches the whole process group; only the parent acts
on it) and are terminated by the parent (:func:`stop_workers`); :func:`stop_signals` makes SIGTERM
raise :class:`Interrupted` like Ctrl-C; a worker that dies (killed, out of memory) turns the
pool's ``BrokenProcessPool`` into one-line :class:`WorkerDied`; :func:`stopped` prints the one
line a command ends with and gives its exit status.

A *projector* (:data:`Projector`) is any callable ``(motions, envs) -> iterable of
(rollout | None, info)`` in input order; a :class:`ProjectionPool`'s :meth:`~ProjectionPool.imap`
is one, the augmentation and the PhysDiff baseline take any (tests inject fakes).
"""

from __future__ import annotations

import contextlib
import functools
import os
import signal
import sys
import threading
from collections.abc import Callable, Iterable, Iterator, Sequence
from concurrent.futures import ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from simdiff.errors import SimdiffError
from simdiff.limits import MAX_WORKERS
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
    """Pool initializer: ignore SIGINT, :func:`limit_threads`, :func:`exit_with_parent`. Pass ``(n, os.getpid())``."""
    _quiet_worker()
    limit_threads(threads)
    exit_with_parent(parent)


def worker_init_quiet(parent: int) -> None:
    """Pool initializer of a pool that needs no thread caps: ignore SIGINT and :func:`exit_with_parent`."""
    _quiet_worker()
    exit_with_parent(parent)


class Interrupted(KeyboardInterrupt):
    """SIGINT (Ctrl-C) or SIGTERM stopped a command (``signum``); its exit status is 128 + signum."""

    def __init__(self, signum: int = signal.SIGINT) -> None:
        super().__init__(signum)
        self.signum = int(signum)


class WorkerDied(SimdiffError):
    """A worker process of a pool died (killed by a signal, out of memory, crashed)."""


def note_progress(exc: BaseException, progress: str) -> None:
    """Attach ``"N of M items done"`` to an :class:`Interrupted` / :class:`WorkerDied` for :func:`stopped`."""
    exc.progress = progress  # type: ignore[attr-defined]


def stopped(exc: BaseException, resumable: bool = True) -> int:
    """Print the one line a command stopped by ``exc`` ends with (stderr); returns its exit status.

    ``KeyboardInterrupt`` / :class:`Interrupted`: ``simdiff: interrupted; N of M clips done, run the
    same command again to resume`` and 128 + the signal (130 for SIGINT, 143 for SIGTERM);
    :class:`WorkerDied`: ``simdiff: error: a worker process died (…); …`` and 1.
    """
    progress = getattr(exc, "progress", None)
    again = "run the same command again to resume" if resumable else "run the same command again"
    tail = f"{progress}, {again}" if progress else again
    if isinstance(exc, WorkerDied):
        print(f"simdiff: error: {exc}; {tail}", file=sys.stderr)
        return 1
    signum = getattr(exc, "signum", signal.SIGINT)
    how = "interrupted" if signum == signal.SIGINT else f"stopped by {signal.Signals(signum).name}"
    print(f"simdiff: {how}; {tail}", file=sys.stderr)
    return 128 + signum


@contextlib.contextmanager
def stop_signals() -> Iterator[None]:
    """While inside (main thread only): SIGTERM raises :class:`Interrupted` (SIGTERM), as Ctrl-C raises
    ``KeyboardInterrupt``, so that a command stopped by a scheduler cleans up as after a Ctrl-C."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def on_term(signum: int, frame: object) -> None:
        raise Interrupted(signum)

    old = signal.signal(signal.SIGTERM, on_term)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, old)


@contextlib.contextmanager
def workers_starting() -> Iterator[None]:
    """Wrap the calls that start worker processes (main thread only): SIGINT and SIGTERM are blocked, and a child
    (spawned or forked) inherits the blocked mask, so neither signal can reach a starting worker before its
    initializer (:func:`_quiet_worker`) sets what they do there; in the parent a signal that arrives meanwhile is
    delivered when the block ends, so a Ctrl-C or a SIGTERM in this window is not lost."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    old = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT, signal.SIGTERM})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)


def _quiet_worker() -> None:
    """In a worker: Ctrl-C is the parent's business; SIGTERM (from the parent) ends it silently."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT, signal.SIGTERM})  # blocked by workers_starting


def _processes(executor: ProcessPoolExecutor) -> list[Any]:
    return list((getattr(executor, "_processes", None) or {}).values())


def stop_workers(executor: ProcessPoolExecutor, processes: Sequence[Any] = ()) -> None:
    """Terminate ``executor``'s worker processes now (their running tasks are lost) and shut it down."""
    procs = list(processes) or _processes(executor)
    for p in _processes(executor) + procs:
        if p.is_alive():
            p.terminate()
    executor.shutdown(wait=True, cancel_futures=True)
    for p in procs:
        p.join(timeout=5)


def worker_died(processes: Sequence[Any]) -> WorkerDied:
    """A :class:`WorkerDied` naming how a worker among ``processes`` (those of a broken pool) ended."""
    for p in processes:
        p.join(timeout=2)
    codes = [p.exitcode for p in processes if p.exitcode not in (None, 0)]
    # the pool terminates (SIGTERM) its other workers once one died: name the first other cause
    code = next((c for c in codes if c != -signal.SIGTERM), codes[0] if codes else None)
    if code is None:
        how = "unknown cause"
    elif code < 0:
        try:
            how = f"signal {-code}, {signal.Signals(-code).name}"
        except ValueError:
            how = f"signal {-code}"
    else:
        how = f"exit status {code}"
    return WorkerDied(f"a worker process died ({how})")


def results_or_died(results: Iterator[Any], processes: Sequence[Any]) -> Iterator[Any]:
    """``results`` of an executor's ``map``, a ``BrokenProcessPool`` turned into :class:`WorkerDied`."""
    try:
        yield from results
    except BrokenProcessPool:
        raise worker_died(processes) from None


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
        if not 0 <= config.workers <= MAX_WORKERS:
            raise SimdiffError(f"workers must be 0 (one per CPU core) to {MAX_WORKERS}, got {config.workers}")
        self.cfg = config
        self._executor: ProcessPoolExecutor | None = None
        self._procs: list[Any] = []  # the executor's worker processes, to tell how one died

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
        starting = len(_processes(self._executor)) < workers  # the workers start on the first tasks submitted
        try:
            with workers_starting() if starting else contextlib.nullcontext():
                results = self._executor.map(_run_one, tasks, chunksize=1)
        except BrokenProcessPool:  # a worker died while idle, between two calls
            raise worker_died(self._procs) from None
        self._procs = _processes(self._executor) or self._procs
        return results_or_died(results, self._procs)

    def close(self) -> None:
        """Shut the worker processes down (a later call starts new ones)."""
        if self._executor is not None:
            self._executor.shutdown(wait=True, cancel_futures=True)
            self._executor = None

    def terminate(self) -> None:
        """Stop the worker processes now, their running tasks lost (after Ctrl-C); a later call starts new ones."""
        if self._executor is not None:
            executor, self._executor = self._executor, None
            stop_workers(executor, self._procs)

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
