"""Body strength under a gravity stronger than Earth's: s = max(1, |g_z| / 9.81).

Strength model: the simulated body is as strong *relative to its own weight* as on Earth.
Under ``|g_z| > 9.81`` every gravity-sized quantity that was tuned at 9.81 is multiplied by s:
the actuators' stiffness ``kp``, damping ``kd`` and force limits, the balance layer's gains
(:func:`scale_balance`) and the root residual's torque bound (:func:`scale_residual`; its force
bound is a fraction of m·|g_z| already). At ``|g_z| ≤ 9.81`` nothing changes (s = 1: the model
and configs are not touched, so Earth, low-gravity and wind rollouts are bit-identical).

Why: the gains and limits (:data:`simdiff.sim.humanoid._GAINS`) were tuned at 9.81. The
tracker's inverse-dynamics feed-forward already knows g (computed under φ's g_z) and asks for up
to s times the Earth torques; with Earth-strong servos (hips and knees saturate at 500 N·m, and
the feed-forward offset τ_ff / kp grows with g), the balance layer's COM gain (kp_xy = 20 1/s²)
below the toppling rate g/h of the body (≈ 22 1/s² at −20) and the pelvis help capped at
Earth's 300 N·m, the body sags and tips. Scaling kp and kd
together keeps τ_ff / kp and the servo lag kd / kp as on Earth; scaling the limits keeps the
torque headroom.

Measured on 24 train clips of the all-source corpus without flight that track at Earth
(augmentation settings): success at
g = −15 / −18 / −20 went from 0.88 / 0.75 / 0.71 (Earth strength) to 1.0 / 1.0 / 1.0; on the
clips both track, median pose d_L2 6.54 / 6.66 / 6.70 → 6.40 / 6.49 / 6.48 and local joint
error 44 / 43 / 44 → 39 / 40 / 39 mm (Earth: 6.29, 41 mm); median residual 47 / 51 / 52 →
48 / 51 / 54 N (Earth 41 N). Actuators alone (kp, kd, limits) reached 0.92 / 0.88 / 0.79,
limits alone 0.88 / 0.75 / 0.67.

Version 3 also stiffens the root residual's pelvis-orientation loop (``residual_gains``:
kp_rot × s, kd_rot × √s). Without it (version 2) standing clips tilt back at high g (a
Bandai-Namco wave at −18.9: pelvis pitch error 13° against 5° at Earth; pose d_L2 8.4 against
5.6), so the pose filter rejects half of the plain pairs at g ∈ [−20, −15). Measured on 40
plain original pairs of that bin drawn from a full augmentation run of the all-source corpus (seed 0): kept 21 → 30,
median pose d_L2 change −0.84; the price is a larger pelvis torque from the residual, median
196 → 242 N·m (Earth rollouts of the same clips: 82 N·m), i.e. 0.18 → 0.22 of the weight
moment m·|g_z|·0.85 m (Earth 0.14); the torque bound itself is the same in both versions.

The actuator scaling is applied to a rollout's private copy of the model (``rollout`` copies
it) by writing ``actuator_gainprm``, ``actuator_biasprm`` and ``actuator_forcerange``: the
cached compiled model is never modified and no XML is rebuilt.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from simdiff.sim.env import EARTH_GRAVITY
from simdiff.sim.residual import ResidualConfig
from simdiff.sim.tracker import PDTrackerConfig


@dataclass(frozen=True)
class StrengthConfig:
    """How actuator strength follows gravity (factor ``s = max(1, |g_z| / reference_gravity)``).

    Attributes:
        gains: multiply every actuator's kp and kd by s.
        limits: multiply every actuator's force limit by s.
        balance: scale the default tracker's balance layer (:func:`scale_balance`): position
            gains (COM ``kp_xy``, pelvis ``kp_rot``) × s, damping (``kd_xy``, ``kd_rot``) × √s.
        residual_torque: the root residual's torque bound × s (:func:`scale_residual`); its
            force bound is already a fraction of m·|g_z|, the torque bound (600·max_force N·m
            ≈ max_force·m·9.81·0.85 m) was not.
        reference_gravity: |g| (m/s²) at which the gains were tuned (9.81).
    """

    gains: bool = True
    limits: bool = True
    balance: bool = True
    residual_torque: bool = True
    residual_gains: bool = True
    reference_gravity: float = abs(EARTH_GRAVITY)

    def factor(self, gravity: float) -> float:
        """s = max(1, |g_z| / reference_gravity) (1 when nothing is scaled)."""
        if not (self.gains or self.limits or self.balance or self.residual_torque or self.residual_gains):
            return 1.0
        return max(1.0, abs(float(gravity)) / self.reference_gravity)


NO_SCALING = StrengthConfig(gains=False, limits=False, balance=False, residual_torque=False, residual_gains=False)
"""Earth-strength actuators at every gravity (the simulator version 1 behaviour)."""


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
    moving = None if b.moving_kp_xy is None else b.moving_kp_xy * s
    return replace(config, balance=replace(b, kp_xy=b.kp_xy * s, kd_xy=b.kd_xy * r, kp_rot=b.kp_rot * s,
                                           kd_rot=b.kd_rot * r, moving_kp_xy=moving))


def scale_residual(config: ResidualConfig, s: float, *, torque: bool = True, gains: bool = False) -> ResidualConfig:
    """The residual config scaled for gravity factor ``s`` (s = 1: unchanged).

    ``torque``: the torque bound × s. The force bound is a fraction of m·|g_z| already; the
    torque bound is fixed in N·m (600·max_force, i.e. max_force·m·9.81 at a 0.85 m lever on
    Earth). Scaling it keeps the pelvis-orientation help the same fraction of the body's
    weight moment as on Earth.
    ``gains``: the pelvis-orientation gains ``kp_rot`` × s and ``kd_rot`` × √s (the same rule
    as :func:`scale_balance`), so that a trunk tilt costs the same fraction of the weight
    moment as on Earth.
    """
    if s == 1.0 or not (torque or gains):
        return config
    out = config
    if torque:
        out = replace(out, max_torque=config.torque_bound * s)
    if gains:
        out = replace(out, kp_rot=config.kp_rot * s, kd_rot=config.kd_rot * math.sqrt(s))
    return out
