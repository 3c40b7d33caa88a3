"""The simulated finish: re-track a generated motion under its φ and keep the simulator's motion.

``simdiff generate --simulate`` (and the viewer's ``simulate`` option) replays the final sample
with the MuJoCo tracking controller under the same φ (:func:`simdiff.sim.project.project`,
flights following gravity) and writes the rollout beside the generated motion: physically
consistent by construction (no penetration beyond the contact model, no foot sliding the
contacts do not allow) at the price of tracking error. The tracking result says how close the
rollout stayed to the generated motion and whether it fell (then the rollout ends at the fall).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from simdiff.errors import SimdiffError
from simdiff.fsio import save_npy, write_json
from simdiff.sim.env import Environment

EARTH = Environment()
"""φ used for a backbone-only model (no environment input): Earth, no wind."""


@dataclass
class SimulatedMotion:
    """The simulated finish of one sample.

    Attributes:
        joints: (T', 22, 3) float32 rollout joints, metres, Y-up, 20 fps (T' = T when tracked to the
            end; shorter after a fall; with the flight clock longer under low gravity).
        tracking: JSON-able tracking result (success, status, fall_frame, errors, residual, CPU and
            wall seconds, physics metrics of the generated and the simulated motion: CLoSD's, and
            ``sliding_own_floor``/``own_floor`` from :func:`simdiff.motion.metrics.own_floor_metrics`,
            since a generated sample that hovers has CLoSD sliding 0 however its feet skate).
    """

    joints: np.ndarray
    tracking: dict[str, Any]


def _finite(value: Any) -> Any:
    """NaN/inf → None, recursively (``generation.json`` refuses non-finite floats)."""
    if isinstance(value, dict):
        return {k: _finite(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_finite(v) for v in value]
    if isinstance(value, (float, np.floating)):
        return float(value) if math.isfinite(float(value)) else None
    if isinstance(value, np.integer):
        return int(value)
    return value


def _physics(joints: np.ndarray) -> dict[str, float]:
    """CLoSD's physics metrics of one motion plus sliding on its own floor (a hovering sample's skating shows there)."""
    from simdiff.motion.metrics import own_floor_metrics, physics_metrics

    return {**physics_metrics(joints), **own_floor_metrics(joints)}


def load_simulator() -> None:
    """Import the simulator stack and compile the humanoid, ahead of a finish (errors surface later, in the finish)."""
    try:
        import simdiff.motion.metrics  # noqa: F401
        import simdiff.sim.project  # noqa: F401
        from simdiff.sim.humanoid import HumanoidConfig, load_model

        load_model(HumanoidConfig())
    except Exception:  # noqa: BLE001 - the finish itself reports any failure with its own message
        pass


def simulate_finish(joints: np.ndarray, env: Environment | None, *, normalizer: Any = None, max_force: float = 0.5,
                    follow_flights: bool = True, force: bool = False, anchor_stance: bool = True) -> SimulatedMotion:
    """Re-track ``joints`` under ``env`` (Earth when None) and return the rollout with its tracking result.

    Args:
        joints: (T, 22, 3) generated joints, metres, Y-up, 20 fps, T ≥ 2.
        env: φ the motion was generated under; None (backbone-only model) tracks under Earth.
        normalizer: feature statistics for d_L2 (None: d_L2 is null).
        max_force: tracker root-residual bound (fraction of m·|g_z|), as in the augmentation.
        follow_flights: flights last as long as φ makes them (the rollout may change length).
        force: allow φ outside the validated range.
        anchor_stance: the finish's retargeting (:func:`simdiff.sim.retarget.finish_retarget`):
            planted feet stay where they touched down, the body's skating drift taken out of the
            reference before tracking, and fast swing feet lifted clear of the floor; and the
            finish's tracker (:func:`simdiff.sim.tracker.finish_tracker_config`), with a second try
            under the slip guard when the rollout fell or slid more than 0.5 mm/frame
            (:func:`simdiff.sim.fallback.finish_fallback`). False: the augmentation's plain
            retargeting and tracker, one try.
    """
    from simdiff.sim.fallback import finish_fallback
    from simdiff.sim.flight import FlightConfig
    from simdiff.sim.project import project
    from simdiff.sim.residual import ResidualConfig
    from simdiff.sim.retarget import finish_retarget
    from simdiff.sim.retarget.contacts import ANCHOR_VERSION
    from simdiff.sim.tracker import finish_tracker_config

    arr = np.asarray(joints, dtype=np.float64)
    if arr.ndim != 3 or arr.shape[1:] != (22, 3) or arr.shape[0] < 2:
        raise SimdiffError(f"--simulate needs joints of shape (T>=2, 22, 3), got {arr.shape}")
    phi = env if env is not None else EARTH
    start = time.perf_counter()
    out, info = project(arr, phi, residual=ResidualConfig(max_force=max_force), normalizer=normalizer, force=force,
                        flight=FlightConfig() if follow_flights else None,
                        retarget=finish_retarget(anchor_stance),
                        tracker_config=finish_tracker_config() if anchor_stance else None,
                        fallback=finish_fallback() if anchor_stance else None)
    wall = time.perf_counter() - start
    out = np.asarray(out, dtype=np.float32)
    tracking = info.to_dict()
    tracking.update(wall_s=wall, env_assumed=env is None, follow_flights=follow_flights, max_force=max_force,
                    anchor_stance=anchor_stance, anchor_version=ANCHOR_VERSION if anchor_stance else None,
                    physics_generated=_physics(arr), physics_simulated=_physics(out) if len(out) >= 2 else None)
    return SimulatedMotion(out, _finite(tracking))


def write_simulated(stem: Path, sim: SimulatedMotion, formats: list[str]) -> dict[str, Path]:
    """Write ``<stem>_simulated_joints.npy`` (and ``_simulated.bvh`` when BVH is asked) and ``<stem>_tracking.json``."""
    written: dict[str, Path] = {}
    if "npy" in formats or not formats:
        written["simulated_joints"] = save_npy(stem.with_name(stem.name + "_simulated_joints.npy"), sim.joints)
    if "bvh" in formats and len(sim.joints) >= 2:
        from simdiff.motion.io.bvh_writer import write_bvh

        written["simulated_bvh"] = write_bvh(stem.with_name(stem.name + "_simulated.bvh"), sim.joints, fps=20.0)
    written["tracking"] = write_json(stem.with_name(stem.name + "_tracking.json"), sim.tracking, indent=2, allow_nan=False)
    return written
