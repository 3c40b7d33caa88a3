"""Project many motions in parallel: local processes by default, Ray for a cluster.

Each task is one ``(joints, env)`` pair; the result is ``(rollout_joints, ProjectionInfo)``
in input order. A task that raises (bad input, MuJoCo error) yields ``(None, error string)``
instead of stopping the batch. Workers build the humanoid once (cached per process).
"""

from __future__ import annotations

import os
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field
from typing import Iterable, Sequence

import numpy as np

from simdiff.errors import SimdiffError
from simdiff.sim.retarget.config import RetargetConfig
from simdiff.sim.env import Environment
from simdiff.sim.project import ProjectionInfo, project
from simdiff.sim.residual import ResidualConfig


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
    """

    workers: int = 0
    backend: str = "process"
    residual: ResidualConfig = ResidualConfig()
    retarget: RetargetConfig = RetargetConfig()
    stats_dir: str | None = None
    force: bool = False
    ray_address: str | None = None
    extra: dict = field(default_factory=dict)


_NORMALIZER_CACHE: dict[str, object] = {}


def _normalizer(stats_dir: str | None):
    if stats_dir is None:
        return None
    if stats_dir not in _NORMALIZER_CACHE:
        from simdiff.motion.normalize import Normalizer

        _NORMALIZER_CACHE[stats_dir] = Normalizer.from_dir(stats_dir)
    return _NORMALIZER_CACHE[stats_dir]


def _run_one(args: tuple[np.ndarray, tuple[float, float, float], PoolConfig]) -> tuple[np.ndarray | None, ProjectionInfo | str]:
    joints, phi, cfg = args
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    try:
        return project(
            joints, Environment(*phi), residual=cfg.residual, retarget=cfg.retarget,
            normalizer=_normalizer(cfg.stats_dir), force=cfg.force,
        )
    except Exception as exc:  # one bad motion must not stop the batch
        return None, f"{type(exc).__name__}: {exc}"


class ProjectionPool:
    """Run :func:`project` over many motions.

    Example:
        >>> pool = ProjectionPool(PoolConfig(workers=2))
        >>> results = pool.map([joints_a, joints_b], [Environment(), Environment(-3.0)])
    """

    def __init__(self, config: PoolConfig = PoolConfig()) -> None:
        if config.backend not in ("process", "ray", "serial"):
            raise SimdiffError(f"unknown pool backend {config.backend!r} (process, ray, serial)")
        self.cfg = config

    def map(
        self, motions: Sequence[np.ndarray], envs: Iterable[Environment] | Environment = Environment()
    ) -> list[tuple[np.ndarray | None, ProjectionInfo | str]]:
        """Project every motion under its environment (one env for all, or one per motion)."""
        envs_list = [envs] * len(motions) if isinstance(envs, Environment) else list(envs)
        if len(envs_list) != len(motions):
            raise SimdiffError(f"{len(motions)} motions but {len(envs_list)} environments")
        for e in envs_list:
            e.validate(force=self.cfg.force)
        tasks = [(np.asarray(m, dtype=np.float32), e.as_tuple(), self.cfg) for m, e in zip(motions, envs_list)]
        workers = self.cfg.workers or os.cpu_count() or 1
        if self.cfg.backend == "serial" or (self.cfg.backend == "process" and workers == 1):
            return [_run_one(t) for t in tasks]
        if self.cfg.backend == "process":
            import multiprocessing as mp

            ctx = mp.get_context("spawn")
            with ProcessPoolExecutor(max_workers=workers, mp_context=ctx) as ex:
                return list(ex.map(_run_one, tasks, chunksize=1))
        return self._map_ray(tasks, workers)

    def _map_ray(self, tasks: list, workers: int) -> list:
        try:
            import ray
        except ImportError as exc:
            raise SimdiffError("the ray backend needs Ray: pip install 'simdiff[cluster]'") from exc
        if not ray.is_initialized():
            ray.init(address=self.cfg.ray_address, ignore_reinit_error=True, log_to_driver=False)
        remote = ray.remote(num_cpus=1)(_run_one)
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
