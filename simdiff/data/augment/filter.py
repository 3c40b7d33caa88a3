"""Which simulated pairs enter the augmented corpus (a pure function of the projection result).

A pair (source clip, φ) is kept when the rollout passes every criterion:

1. ``failed``: it tracked to the end (no fall, no instability);
2. ``faithfulness``: it still performs the source's motion, measured so that what φ changes
   (timing, flight height and length, speed) is not punished: ``d_l2_pose`` (pose channels
   of the 263-d features against the source re-timed onto the rollout's flight clock, see
   :mod:`simdiff.sim.faithfulness`) at most ``max_pose_d_l2``. The paper's d_L2 ≤ 7 rejected
   exactly the rollouts gravity changed (Earth motions re-tracked at g = −3: median d_L2 9.7);
   it stays available as ``max_d_l2`` (off by default);
3. ``residual``: it was not carried by the tracker's root residual: the mean residual force
   over the rollout at most ``max_residual_n`` **newtons**, the same for every φ.

Why an absolute budget: the residual corrects the tracker's stance errors (foot placement,
retargeting), whose size does not scale with g. A relative budget of 0.1·m·|g_z|
is 71 N on Earth but 11.5 N at g = −1.6, below what the stance correction needs on any
motion, so it rejected nearly every low-gravity pair (5 of 97 at g ≥ −3.2). The default,
70.6 N = 0.1·72 kg·9.81 m/s², keeps the Earth threshold where it was (so the Earth keep rate
does not move) and applies it unchanged at every g ≤ 9.81 (the residual is zero in the air
(gated, audited), so it never carries a flight; against the wind it is velocity-only in xy).
Above Earth gravity the body is as strong relative to its weight as on Earth
(:mod:`simdiff.sim.strength`, s = max(1, |g_z|/9.81)) and the loads its stance corrections
fight grow with the weight, so the budget is 70.6 N · s there (``residual_follows_strength``;
measured on 24 clips without flight: median residual 41 N at Earth, 54-58 N at −20, 300 N·m
torque cap scaled the same way by the tracker).

Calibration of ``max_pose_d_l2`` = 5.2: on the Earth rollouts of 24 CMU clips (with the
official HumanML3D Mean/Std), a filter without the clock (d_L2 ≤ 7, ≤ 0.1·m·g) kept 11;
the 11th smallest pose d_L2 of the tracked, residual-ok Earth rollouts with the clock was
5.14, rounded up; with the final clock settings 5.2 keeps 12 of those 24 (the equal-rate
point is 4.62), so the Earth keep rate is not lower.
Like d_L2 it is in normalised units, so it depends on the normaliser: on the all-source corpus
with its own Mean/Std, 5.2 keeps 18 % at Earth. ``max_pose_d_l2 = "auto"`` (the CLI default in
paired and binary mode) calibrates it per run so that the Earth keep rate is ``earth_keep``
(0.66), see :mod:`simdiff.data.augment.decide`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from simdiff.errors import SimdiffError

REASONS: tuple[str, ...] = ("kept", "error", "failed", "faithfulness", "residual")
"""Outcome labels, in the order the checks are applied."""
CRITERIA: tuple[str, ...] = ("failed", "faithfulness", "residual")
"""The criteria, each also judged on its own by :func:`rejections`."""
AUTO: str = "auto"
"""``max_pose_d_l2`` value asking for the per-run Earth calibration (:mod:`simdiff.data.augment.decide`)."""
HUMANOID_MASS: float = 72.0
"""kg; converts records that only carry the relative residual (``force_mean_mg``) to newtons."""


@dataclass(frozen=True)
class FilterConfig:
    """Thresholds of :func:`keep_pair` (None switches a criterion off).

    Attributes:
        max_pose_d_l2: largest pose d_L2 against the re-timed source (normalised feature units),
            or ``"auto"``: calibrated at finalize on the run's Earth pairs (needs the records).
        max_residual_n: largest mean root residual force (N), for every φ.
        max_d_l2: largest paper d_L2 (eq. 13; the paper's 7.0), off by default.
        max_residual: largest mean residual force as a fraction of m·|g_z| (the relative
            budget), off by default.
        earth_keep: with ``"auto"``, the Earth keep rate the threshold is calibrated to reach.
        residual_follows_strength: above Earth gravity the residual budget is
            ``max_residual_n · s`` with the body-strength factor ``s = max(1, |g_z|/9.81)``
            (:mod:`simdiff.sim.strength`); at ``|g_z| ≤ 9.81`` it stays ``max_residual_n``.
    """

    max_pose_d_l2: float | str | None = 5.2
    max_residual_n: float | None = 70.6
    max_d_l2: float | None = None
    max_residual: float | None = None
    earth_keep: float = 0.66
    residual_follows_strength: bool = True


def _get(info: Any, key: str, default: Any = None) -> Any:
    if isinstance(info, dict):
        return info.get(key, default)
    return getattr(info, key, default)


def _over(value: Any, bound: float | None) -> bool:
    """True when a bound is set and the value is missing, not finite, or above it."""
    if bound is None:
        return False
    if value is None:
        return True
    v = float(value)
    return not math.isfinite(v) or v > bound


def residual_newtons(info: Any) -> float:
    """Mean residual force (N) of a projection record (also from the older relative field)."""
    residual = _get(info, "residual", {}) or {}
    if "force_mean_n" in residual:
        return float(residual["force_mean_n"])
    env = _get(info, "env", None)
    g = abs(float(env[0])) if env else 9.81
    return float(residual.get("force_mean_mg", 0.0)) * HUMANOID_MASS * g


def residual_budget(info: Any, config: FilterConfig) -> float | None:
    """The residual force budget (N) for this pair's φ (None: the criterion is off)."""
    if config.max_residual_n is None:
        return None
    if not config.residual_follows_strength:
        return float(config.max_residual_n)
    env = _get(info, "env", None)
    g = abs(float(env[0])) if env else 9.81
    return float(config.max_residual_n) * max(1.0, g / 9.81)


def rejections(info: Any, config: FilterConfig = FilterConfig()) -> dict[str, bool]:
    """Each criterion judged on its own: ``{criterion: rejects}`` (an error rejects all)."""
    if isinstance(config.max_pose_d_l2, str):
        raise SimdiffError(f"max_pose_d_l2={config.max_pose_d_l2!r} must be calibrated first "
                           "(simdiff.data.augment.decide.decide)")
    if info is None or isinstance(info, str):
        return {c: True for c in CRITERIA}
    residual = _get(info, "residual", {}) or {}
    return {
        "failed": not bool(_get(info, "success", False)),
        "faithfulness": _over(_get(info, "d_l2_pose"), config.max_pose_d_l2) or _over(_get(info, "d_l2"), config.max_d_l2),
        "residual": _over(residual_newtons(info), residual_budget(info, config))
        or _over(residual.get("force_mean_mg", 0.0), config.max_residual),
    }


def keep_pair(info: Any, config: FilterConfig = FilterConfig()) -> tuple[bool, str]:
    """Decide one projected pair.

    Args:
        info: a :class:`simdiff.sim.project.ProjectionInfo`, its ``to_dict()``, or an error
            string (a projection that raised).
        config: thresholds.
    Returns:
        (kept, reason) with reason one of :data:`REASONS` (the first criterion that rejects).
    """
    if info is None or isinstance(info, str):
        return False, "error"
    rej = rejections(info, config)
    for c in CRITERIA:
        if rej[c]:
            return False, c
    return True, "kept"
