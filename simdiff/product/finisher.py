"""The simulated finish in a separate process that starts before the model loads.

The simulator stack (MuJoCo, scipy, the humanoid, and torch for the features behind d_L2) takes
about 1 CPU-s to import on top of torch. On a thread it holds the GIL and slows the sampling
by about as much as it loads (measured on 2 cores: a thread saved 0.4–1.0 s of the 2.4 s that
``--simulate`` added). In a process started at the beginning of ``simdiff generate --simulate``
it imports on another core while this process imports torch, loads the model and samples, so
the command afterwards waits only for the tracking itself. The rollout is the same function with
the same inputs (:func:`simdiff.product.simulate.simulate_finish`), so the result is the same.

A machine with one CPU has no core to give the worker: :func:`start_finisher` returns None there
and the finish runs in this process, its imports on a thread
(:func:`simdiff.product.pipeline.warm_simulator`). On a busy machine the worker competes with the
other jobs like any process.
"""

from __future__ import annotations

import os
import signal
from concurrent.futures import Future, ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from typing import Any

import numpy as np

from simdiff.errors import SimdiffError
from simdiff.sim.env import Environment


def _init_worker(parent: int) -> None:
    """Ctrl-C is the parent's to handle (it shuts the worker down); one BLAS/torch thread (the finish is serial);
    the worker ends when its parent is gone."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    from simdiff.sim.pool import worker_init

    worker_init(1, parent)


def _warm() -> bool:
    """Import the simulator stack, the feature conversion of d_L2 and compile the humanoid."""
    from simdiff.product.simulate import load_simulator

    load_simulator()
    try:
        import simdiff.motion.features  # noqa: F401 - d_L2's joints → features (torch)
    except ImportError:
        pass
    return True


def _finish(joints: np.ndarray, env: Environment | None, normalizer: Any, force: bool) -> Any:
    """:func:`simulate_finish` in the worker; a user error comes back as a plain :class:`SimdiffError`."""
    from simdiff.product.simulate import simulate_finish

    try:
        return simulate_finish(joints, env, normalizer=normalizer, force=force)
    except SimdiffError as exc:  # subclasses may not survive pickling with their own __init__
        raise SimdiffError(str(exc)) from None


def _stopped(exc: BaseException) -> SimdiffError:
    """The one-line error for a worker that died (killed, out of memory, a crash in native code)."""
    return SimdiffError(f"the simulator process stopped unexpectedly ({exc}); run without --simulate, or with "
                        "SIMDIFF_FINISH_WORKERS=0 to finish in this process")


class Finisher:
    """A small process pool that re-tracks generated samples under their φ.

    Example:
        >>> with Finisher() as finisher:          # starts importing the simulator now
        ...     future = finisher.submit(joints, Environment(-3.7))
        ...     simulated = finisher.result(future)
    """

    def __init__(self, workers: int = 1) -> None:
        import multiprocessing as mp

        self.workers = max(1, int(workers))
        self._executor: ProcessPoolExecutor | None = ProcessPoolExecutor(
            max_workers=self.workers, mp_context=mp.get_context("spawn"), initializer=_init_worker,
            initargs=(os.getpid(),))
        self._warm = [self._executor.submit(_warm) for _ in range(self.workers)]

    def __enter__(self) -> "Finisher":
        return self

    def __exit__(self, exc_type: object, *rest: object) -> None:
        self.close(cancel=exc_type is not None)

    def submit(self, joints: np.ndarray, env: Environment | None, normalizer: Any = None,
               force: bool = False) -> Future:
        """Queue the finish of one (T, 22, 3) motion (metres, Y-up, 20 fps) under ``env``."""
        if self._executor is None:
            raise SimdiffError("the simulated-finish worker is closed")
        try:
            return self._executor.submit(_finish, np.asarray(joints), env, normalizer, force)
        except BrokenProcessPool as exc:
            raise _stopped(exc) from None

    def result(self, future: Future) -> Any:
        """The :class:`~simdiff.product.simulate.SimulatedMotion` of a submitted finish (its error re-raised)."""
        try:
            return future.result()
        except BrokenProcessPool as exc:
            raise _stopped(exc) from None

    def close(self, cancel: bool = False) -> None:
        """Shut the worker down; with ``cancel`` (an error or Ctrl-C) without waiting for a running finish."""
        executor, self._executor = self._executor, None
        if executor is None:
            return
        processes = list((getattr(executor, "_processes", None) or {}).values())  # no public way to stop a worker
        executor.shutdown(wait=False, cancel_futures=cancel)
        for proc in processes:  # idle after the last result (or cancelled): its exit would only tear down imports
            if proc.is_alive():
                proc.terminate()


WORKERS_ENV = "SIMDIFF_FINISH_WORKERS"
"""Environment variable: worker processes of the simulated finish (0: in this process; unset: automatic)."""


def start_finisher(n_motions: int, cpus: int | None = None) -> Finisher | None:
    """A :class:`Finisher` for ``n_motions`` finishes, or None (finish in this process) on one CPU or
    with ``SIMDIFF_FINISH_WORKERS=0``.

    Workers: ``$SIMDIFF_FINISH_WORKERS`` when set, else one per motion, at most the CPUs less one (this
    process samples on the rest). The load average is not consulted: its one-minute window still counts
    the previous command's work, so it would switch the worker on and off between identical commands
    run back to back.
    """
    raw = os.environ.get(WORKERS_ENV, "").strip()
    if raw:
        try:
            workers = int(raw)
        except ValueError:
            raise SimdiffError(f"{WORKERS_ENV} must be a whole number of processes, got {raw!r}") from None
        if workers < 0:
            raise SimdiffError(f"{WORKERS_ENV} must be 0 (in this process) or more, got {workers}")
    else:
        cpus = (os.cpu_count() or 1) if cpus is None else cpus
        workers = cpus - 1
    workers = min(workers, n_motions)
    return Finisher(workers=workers) if workers >= 1 else None
