"""Actuator strength under a gravity stronger than Earth's: s = max(1, |g_z| / 9.81).

Strength model: the simulated body is as strong *relative to its own weight* as on Earth.
Under ``|g_z| > 9.81`` every actuator's stiffness ``kp``, damping ``kd`` and force limit are
multiplied by ``s = |g_z| / 9.81``; at ``|g_z| ≤ 9.81`` nothing changes (s = 1, the model is
not touched, so Earth, low-gravity and wind rollouts are bit-identical to unscaled ones).

Why: the PD gains and force limits (:data:`simdiff.sim.humanoid._GAINS`) were tuned at 9.81.
The tracker's inverse-dynamics feed-forward already knows g (it is computed under φ's g_z) and
asks for up to s times the Earth torques, but the servos stay Earth-strong: hips and knees
saturate at 500 N·m, and the feed-forward offset τ_ff / kp grows with g until the target
leaves the joint range (targets are clipped there), so the body sags under load and the
root residual carries it. Scaling kp and kd together keeps the servo's natural frequency per
unit load and the feed-forward offset τ_ff / kp as on Earth; scaling the limits keeps the
torque headroom. Measured (``benchmarks/bench_high_gravity.py``,
``reports/augment/high_gravity.json``): see :data:`StrengthConfig` defaults.

The scaling is applied to a rollout's private copy of the model (``rollout`` copies it), by
writing ``actuator_gainprm``, ``actuator_biasprm`` and ``actuator_forcerange``, so the cached
compiled model is never modified and no XML is rebuilt.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from simdiff.sim.env import EARTH_GRAVITY
from simdiff.sim.tracker import PDTrackerConfig


@dataclass(frozen=True)
class StrengthConfig:
    """How actuator strength follows gravity (factor ``s = max(1, |g_z| / reference_gravity)``).

    Attributes:
        gains: multiply every actuator's kp and kd by s.
        limits: multiply every actuator's force limit by s.
        balance: scale the default tracker's balance layer (:func:`scale_balance`): position
            gains (COM ``kp_xy``, pelvis ``kp_rot``) × s, damping (``kd_xy``, ``kd_rot``) × √s.
        reference_gravity: |g| (m/s²) at which the gains were tuned (9.81).
    """

    gains: bool = True
    limits: bool = True
    balance: bool = True
    reference_gravity: float = abs(EARTH_GRAVITY)

    def factor(self, gravity: float) -> float:
        """s = max(1, |g_z| / reference_gravity) (1 when nothing is scaled)."""
        if not (self.gains or self.limits or self.balance):
            return 1.0
        return max(1.0, abs(float(gravity)) / self.reference_gravity)


NO_SCALING = StrengthConfig(gains=False, limits=False, balance=False)
"""Earth-strength actuators at every gravity (the behaviour before issue 13)."""


def apply_strength(model, gravity: float, config: StrengthConfig | None) -> float:
    """Scale ``model``'s actuators in place for gravity ``gravity`` (m/s²); returns s.

    Only call this on a private copy of a compiled humanoid (``copy.copy(model)``). With s = 1
    (``|g_z| ≤ 9.81``, or ``config`` None / :data:`NO_SCALING`) the model is left untouched.
    The actuators are the humanoid's affine PD servos: ``gainprm[0] = kp``,
    ``biasprm[1:3] = (−kp, −kd)``, ``forcerange = (−fmax, fmax)``.
    """
    if config is None:
        return 1.0
    s = config.factor(gravity)
    if s == 1.0:
        return 1.0
    if config.gains:
        model.actuator_gainprm[:, 0] *= s
        model.actuator_biasprm[:, 1:3] *= s
    if config.limits:
        model.actuator_forcerange[:] *= s
    return s


def scale_balance(config: PDTrackerConfig, s: float) -> PDTrackerConfig:
    """The tracker config with its balance layer scaled for gravity factor ``s`` (s = 1: unchanged).

    The balance layer steers the COM and pelvis of a body that topples like an inverted
    pendulum, ẍ = (g/h)·x: the toppling acceleration (and torque m·g·h·θ) grows with |g_z|.
    Position gains × s keep the closed loop's stiffness above the toppling term by the same
    ratio as on Earth (kp_xy = 20 1/s² against g/h ≈ 11 1/s² at 9.81, but 22 1/s² at −20,
    where the unscaled loop no longer holds the COM); damping × √s keeps the damping ratio
    (the loop's natural frequency grows by √s). The capture-point step and the foot's
    centre-of-pressure bounds already use g.
    """
    if s == 1.0 or config.balance is None:
        return config
    b = config.balance
    r = math.sqrt(s)
    return replace(config, balance=replace(b, kp_xy=b.kp_xy * s, kd_xy=b.kd_xy * r, kp_rot=b.kp_rot * s,
                                           kd_rot=b.kd_rot * r))
