"""The one process pool: persistent workers, single-threaded BLAS in workers, the augmentation's projector on it."""

from __future__ import annotations

import multiprocessing as mp
import os
from concurrent.futures import ProcessPoolExecutor

import numpy as np
import pytest

pytest.importorskip("mujoco")
threadpoolctl = pytest.importorskip("threadpoolctl")

from simdiff.errors import SimdiffError  # noqa: E402
from simdiff.sim import synthetic  # noqa: E402
from simdiff.sim.env import Environment  # noqa: E402
from simdiff.sim.pool import PoolConfig, ProjectionPool, limit_threads  # noqa: E402


def _blas_threads() -> tuple[int, str | None]:
    """Run in a worker: the largest BLAS / OpenMP pool size numpy sees, and OMP_NUM_THREADS."""
    info = threadpoolctl.threadpool_info()
    return max((i["num_threads"] for i in info), default=1), os.environ.get("OMP_NUM_THREADS")


def test_limit_threads_resizes_pools_already_loaded(monkeypatch):
    torch = pytest.importorskip("torch")
    for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        monkeypatch.delenv(var, raising=False)
    threads = torch.get_num_threads()
    with threadpoolctl.threadpool_limits(limits=None):  # restores the pools on exit
        with threadpoolctl.threadpool_limits(limits=2):
            assert all(i["num_threads"] <= 2 for i in threadpoolctl.threadpool_info())
            limit_threads(1)  # numpy (and torch) are long imported here
            assert [i["num_threads"] for i in threadpoolctl.threadpool_info()] == [1] * len(threadpoolctl.threadpool_info())
            assert torch.get_num_threads() == 1
            assert os.environ["OMP_NUM_THREADS"] == "1"
    torch.set_num_threads(threads)


def test_spawned_worker_with_the_pool_initializer_is_single_threaded():
    ctx = mp.get_context("spawn")
    with ProcessPoolExecutor(1, mp_context=ctx, initializer=limit_threads, initargs=(1,)) as ex:
        blas, omp = ex.submit(_blas_threads).result(timeout=120)
    assert blas == 1 and omp == "1"


def test_pool_keeps_its_workers_across_calls_and_matches_serial():
    motions = [synthetic.standing(12), synthetic.squat(12)]
    envs = [Environment(), Environment(-3.0)]
    serial = ProjectionPool(PoolConfig(backend="serial")).map(motions, envs)
    with ProjectionPool(PoolConfig(workers=2)) as pool:
        first = pool.map(motions, envs)
        executor = pool._executor
        second = list(pool(motions[::-1], envs[::-1]))  # a pool is a projector
        assert pool._executor is executor and executor is not None
    assert pool._executor is None
    for (a, ia), (b, ib), (c, ic) in zip(serial, first, second[::-1]):
        assert ia.success == ib.success == ic.success
        assert np.allclose(a, b) and np.allclose(a, c)


def test_imap_reports_a_bad_environment_per_pair_and_map_refuses_it():
    pool = ProjectionPool(PoolConfig(backend="serial"))
    out = list(pool.imap([synthetic.standing(12)], [Environment(-50.0)]))
    assert out[0][0] is None and "-50" in out[0][1]
    with pytest.raises(SimdiffError, match="-50"):
        pool.map([synthetic.standing(12)], [Environment(-50.0)])
    bad = pool.map([np.zeros((3, 22, 3))])  # a bad motion is that pair's error, not the batch's
    assert bad[0][0] is None and "too short" in bad[0][1]
    with pytest.raises(SimdiffError, match="2 motions but 1"):
        list(pool.imap([synthetic.standing(12)] * 2, [Environment()]))


def test_sim_projector_runs_on_the_projection_pool():
    from simdiff.data.augment.projector import SimProjector

    proj = SimProjector(None, workers=1, backend="serial", max_force=0.25)
    assert isinstance(proj._pool, ProjectionPool)
    assert proj._pool.cfg.residual.max_force == 0.25
    (joints, info), = list(proj([synthetic.standing(12)], [Environment()]))
    assert joints.shape[1:] == (22, 3) and info.success
    with pytest.raises(SimdiffError, match="backend"):
        SimProjector(None, backend="threads")


_ORPHAN_PARENT = """
import os, sys, time
import multiprocessing as mp
from concurrent.futures import ProcessPoolExecutor
from simdiff.sim.pool import worker_init
if __name__ == "__main__":
    ex = ProcessPoolExecutor(1, mp_context=mp.get_context("spawn"), initializer=worker_init, initargs=(1, os.getpid()))
    print(ex.submit(os.getpid).result(timeout=120), flush=True)
    ex.submit(time.sleep, 600)
    time.sleep(600)
"""


def _running(pid: int) -> bool:
    """True while ``pid`` exists and is not a zombie (an orphan's zombie may wait for a reaper that never comes)."""
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().rsplit(")", 1)[1].split()[0] != "Z"
    except FileNotFoundError:
        return False


@pytest.mark.skipif(not os.path.isdir("/proc/self"), reason="reads process states from /proc")
def test_pool_workers_exit_when_their_parent_is_killed(tmp_path):
    """A command killed without its cleanup (SIGKILL here) leaves no worker simulating on as an orphan."""
    import signal
    import subprocess
    import sys
    import time

    script = tmp_path / "parent.py"
    script.write_text(_ORPHAN_PARENT)
    parent = subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE, text=True)
    try:
        worker = int(parent.stdout.readline())
        assert _running(worker)
        parent.send_signal(signal.SIGKILL)
        parent.wait(timeout=30)
        deadline = time.monotonic() + 20
        while _running(worker) and time.monotonic() < deadline:
            time.sleep(0.2)
        assert not _running(worker), "the worker outlived its killed parent"
    finally:
        parent.kill()
