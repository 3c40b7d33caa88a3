"""A second rollout with other tracker settings when the first fell or its feet slid.

A tracked rollout is chaotic in its details: the same generated motion tracked with two close
tracker settings can slide 0.2 mm/frame with one and 0.8 with the other, or fall with one only.
Both rollouts are simulations under the same φ, so
either is physically valid; :func:`simdiff.sim.project.project` keeps the first unless it fell
or its CLoSD foot sliding is above :attr:`FallbackConfig.sliding_trigger`, and then keeps the
better of the two (a rollout tracked to the end over a fall, then the lower sliding).

Used by the simulated finish (:func:`simdiff.product.simulate.simulate_finish`, the experiments'
finish row) with :func:`finish_fallback`; the augmentation and
PhysDiff make one try.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from simdiff.errors import SimdiffError
from simdiff.sim.retime import better
from simdiff.sim.slip_guard import FINISH_SLIP_GUARD
from simdiff.sim.tracker import PDTrackerConfig, finish_tracker_config


@dataclass(frozen=True)
class FallbackConfig:
    """When :func:`simdiff.sim.project.project` makes a second try, and with which tracker.

    Attributes:
        tracker_config: the default tracker's settings for the second try.
        sliding_trigger: retry a rollout tracked to the end whose CLoSD sliding (mm/frame, the
            foot-joint displacement while near the floor, :func:`simdiff.motion.metrics.physics_metrics`)
            is above this; a rollout that fell is always retried.
    """

    tracker_config: PDTrackerConfig
    sliding_trigger: float = 0.5

    def __post_init__(self) -> None:
        if not (math.isfinite(self.sliding_trigger) and self.sliding_trigger >= 0.0):
            raise SimdiffError(f"fallback sliding_trigger must be a finite number >= 0, got {self.sliding_trigger}")

    def should_retry(self, status: str, sliding: float) -> bool:
        """True when a first rollout (``status``, its CLoSD sliding in mm/frame) earns a second try."""
        return status != "ok" or not (np.isfinite(sliding) and sliding <= self.sliding_trigger)


def rollout_sliding(joints: np.ndarray) -> float:
    """CLoSD sliding (mm/frame) of a returned rollout (T', 22, 3), HumanML3D floor; NaN under 2 frames."""
    if len(joints) < 2:
        return float("nan")
    from simdiff.motion.metrics import physics_metrics

    return float(physics_metrics(np.asarray(joints, dtype=np.float32))["sliding"])


better_rollout = better
"""True when ``second`` (status, sliding) beats ``first``: tracked to the end first, then lower sliding
(:func:`simdiff.sim.retime.better`, the re-timed try's rule)."""


FINISH_FALLBACK: bool = True
"""Whether the simulated finish makes the second try."""

FINISH_FALLBACK_SLIDING: float = 0.5
""":attr:`FallbackConfig.sliding_trigger` of the simulated finish (mm/frame): the target for the
finish's output; a rollout at or below it is kept without a second try."""


def finish_fallback() -> FallbackConfig | None:
    """The simulated finish's second try: the finish's tracker with the slip guard
    (:data:`simdiff.sim.slip_guard.FINISH_SLIP_GUARD`), when the first rollout fell or slid more than
    :data:`FINISH_FALLBACK_SLIDING`; None when :data:`FINISH_FALLBACK` is off."""
    if not FINISH_FALLBACK:
        return None
    from dataclasses import replace

    return FallbackConfig(replace(finish_tracker_config(), slip_guard=FINISH_SLIP_GUARD), FINISH_FALLBACK_SLIDING)
