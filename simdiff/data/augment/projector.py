"""How the augmentation runs the simulator: :class:`SimProjector` on :class:`simdiff.sim.pool.ProjectionPool`.

A *projector* (:data:`simdiff.sim.pool.Projector`) is any callable ``(motions, envs) ->
iterable of (rollout | None, info)`` yielding results in input order (``info`` a
:class:`ProjectionInfo`, its dict, or an error string); tests inject fakes.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from dataclasses import dataclass

import numpy as np

from simdiff.sim.env import Environment
from simdiff.sim.fallback import finish_fallback
from simdiff.sim.flight import FlightConfig
from simdiff.sim.pool import PoolConfig, ProjectionPool, Projector, Result
from simdiff.sim.residual import ResidualConfig
from simdiff.sim.retime import RetimeConfig
from simdiff.sim.retarget.config import finish_retarget
from simdiff.sim.tracker import finish_tracker_config

__all__ = ["Projector", "Result", "SimProjector"]


@dataclass
class SimProjector:
    """The default projector: a :class:`ProjectionPool` kept alive across shards.

    Args:
        stats_dir: folder with Mean.npy/Std.npy for d_L2 (the source corpus).
        workers: processes (``process``) or concurrent tasks (``ray``); 0 = all cores.
        backend: ``process`` (a pool kept alive across shards), ``ray`` or ``serial``.
        max_force: root residual bound (fraction of m·|g_z|) passed to the tracker.
        flight: the flight clock (default on: flights last as long as φ makes them, the
            rollout may be longer than its source); None: the reference's own clock.
        retime: under |g_z| < 9.81, a second try on the source slowed to the same Froude number
            when the first rollout fell or strayed (:mod:`simdiff.sim.retime`; the augmentation's
            default); None: one try (PhysDiff, the evaluation's re-tracking).
        anchor_stance: the simulated finish's retargeting and tracker
            (:func:`simdiff.sim.retarget.finish_retarget`: planted feet stay put, swing feet clear the
            floor; :func:`simdiff.sim.tracker.finish_tracker_config`: a longer lead; a second try with
            the slip guard when the rollout fell or slid, :func:`simdiff.sim.fallback.finish_fallback`);
            off for augmentation and PhysDiff.
    Raises:
        SimdiffError: an unknown backend.
    """

    stats_dir: str | None
    workers: int = 0
    backend: str = "process"
    max_force: float = 0.5
    flight: FlightConfig | None = FlightConfig()
    anchor_stance: bool = False
    retime: RetimeConfig | None = None

    def __post_init__(self) -> None:
        self._pool = ProjectionPool(PoolConfig(workers=self.workers, backend=self.backend, stats_dir=self.stats_dir,
                                               residual=ResidualConfig(max_force=self.max_force), flight=self.flight,
                                               retime=self.retime,
                                               retarget=finish_retarget(self.anchor_stance),
                                               tracker_config=finish_tracker_config() if self.anchor_stance else None,
                                               fallback=finish_fallback() if self.anchor_stance else None))

    def __call__(self, motions: Sequence[np.ndarray], envs: Sequence[Environment]) -> Iterator[Result]:
        return self._pool.imap(motions, envs)

    def close(self) -> None:
        """Shut the worker processes down."""
        self._pool.close()

    def terminate(self) -> None:
        """Stop the worker processes now, their running pairs lost (Ctrl-C, SIGTERM, a dead worker)."""
        self._pool.terminate()
