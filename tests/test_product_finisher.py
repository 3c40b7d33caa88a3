"""The simulated finish in a worker process (``simdiff generate --simulate``): same result, clear errors."""

from __future__ import annotations

import time

import numpy as np
import pytest

from simdiff.errors import SimdiffError
from simdiff.motion.quaternion import cross3
from simdiff.motion.synthetic import walk
from simdiff.product.finisher import WORKERS_ENV, Finisher, start_finisher
from simdiff.product.simulate import simulate_finish
from simdiff.sim.env import Environment


def test_the_worker_gives_the_same_rollout_as_this_process() -> None:
    motion = walk(24, speed=0.6)
    here = simulate_finish(motion, Environment(-3.7))
    with Finisher() as finisher:
        there = finisher.result(finisher.submit(motion, Environment(-3.7)))
    np.testing.assert_array_equal(there.joints, here.joints)
    for key in ("status", "n_out", "fall_frame", "err_mm", "env", "physics_simulated"):
        assert there.tracking[key] == here.tracking[key], key


def test_a_bad_motion_fails_with_the_finish_own_message() -> None:
    with Finisher() as finisher:
        future = finisher.submit(np.zeros((1, 22, 3)), None)
        with pytest.raises(SimdiffError, match=r"\(T>=2, 22, 3\)"):
            finisher.result(future)
        finisher.close()
        with pytest.raises(SimdiffError, match="closed"):
            finisher.submit(np.zeros((2, 22, 3)), None)


def test_cancel_stops_a_running_finish() -> None:
    finisher = Finisher()
    finisher.submit(walk(200, speed=0.6), None)
    processes = list(finisher._executor._processes.values())
    finisher.close(cancel=True)
    # SIGTERM, then SIGKILL after 2 s. Poll rather than trust one join(): the executor's own thread may reap the
    # worker first, and until it records the exit code, this thread's is_alive() still says True.
    deadline = time.monotonic() + 30
    while any(proc.is_alive() for proc in processes) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert not any(proc.is_alive() for proc in processes)


@pytest.mark.parametrize(("cpus", "workers"), [(1, None), (2, 1), (8, 3)])
def test_a_worker_only_where_there_is_a_second_cpu(cpus: int, workers: int | None,
                                                   monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv(WORKERS_ENV, raising=False)
    finisher = start_finisher(3, cpus=cpus)
    try:
        assert (finisher.workers if finisher is not None else None) == workers
    finally:
        if finisher is not None:
            finisher.close(cancel=True)


def test_cross3_is_numpys_cross_bit_for_bit() -> None:
    rng = np.random.default_rng(0)
    for sa, sb in [((3,), (5, 3)), ((1, 72, 3), (22, 72, 3)), ((7, 3), (7, 3))]:
        a, b = rng.normal(size=sa) * 1e3, rng.normal(size=sb)
        assert np.array_equal(cross3(a, b), np.cross(a, b))


def test_the_environment_variable_sets_the_workers(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv(WORKERS_ENV, "0")
    assert start_finisher(4, cpus=8) is None
    for bad in ("two", "-1"):
        monkeypatch.setenv(WORKERS_ENV, bad)
        with pytest.raises(SimdiffError, match=f"{WORKERS_ENV}.*{bad}"):
            start_finisher(4)


def test_a_killed_worker_is_a_one_line_error() -> None:
    import os
    import signal

    finisher = Finisher()
    try:
        finisher._warm[0].result(timeout=120)
        for proc in list(finisher._executor._processes.values()):
            os.kill(proc.pid, signal.SIGKILL)
            proc.join(timeout=10)
        with pytest.raises(SimdiffError, match="simulator process stopped unexpectedly"):
            finisher.result(finisher.submit(walk(8, speed=0.5), None))
    finally:
        finisher.close(cancel=True)
