"""Which simulated pairs enter the augmented corpus (a pure function of the projection result).

A pair (source clip, φ) is kept when the rollout

1. tracked to the end (``success``: no fall, no instability, all frames returned);
2. stays close to the source: ``d_L2 ≤ 7.0`` (paper eq. 13, mean per-frame L2 distance of
   normalised 263-d features; NaN fails);
3. was not carried by the tracker's root residual: the mean residual force over the rollout
   ``residual.force_mean_mg`` (a fraction of the character's weight m·|g_z| under φ) is at
   most ``max_residual``.

Why a residual budget, and why 0.1 by default: the PD tracker may push the pelvis with a
contact-gated, non-physical wrench (up to 0.5·m·g by default, see
:mod:`simdiff.sim.residual`). A rollout that leans on it is not a motion that obeys φ: in
particular the residual can cancel the wind (10 N is only 0.014·m·g for 72 kg). On the 40
CMU clips of ``reports/sim/summary.md`` the tracked jumps and jacks, which look physical,
use 0.06–0.13·m·g on average, walks and runs that the residual props up 0.15–0.25·m·g;
0.1·m·g separates the two groups (7 of the 40 clips, 18 %, track at Earth gravity within it
with the first-pass tracker). Raise it (``--max-residual``) for more data of
lower physical fidelity; 0 keeps only residual-free rollouts (the paper's strict setting).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

REASONS: tuple[str, ...] = ("kept", "error", "failed", "d_l2", "residual")
"""Outcome labels, in the order the checks are applied."""


@dataclass(frozen=True)
class FilterConfig:
    """Thresholds of :func:`keep_pair`.

    Attributes:
        max_d_l2: largest d_L2 (normalised feature units) kept; the paper uses 7.0.
        max_residual: largest mean root residual force as a fraction of m·|g_z| (see module docstring).
    """

    max_d_l2: float = 7.0
    max_residual: float = 0.1


def _get(info: Any, key: str, default: Any = None) -> Any:
    if isinstance(info, dict):
        return info.get(key, default)
    return getattr(info, key, default)


def keep_pair(info: Any, config: FilterConfig = FilterConfig()) -> tuple[bool, str]:
    """Decide one projected pair.

    Args:
        info: a :class:`simdiff.sim.project.ProjectionInfo`, its ``to_dict()``, or an error
            string (a projection that raised).
        config: thresholds.
    Returns:
        (kept, reason) with reason one of :data:`REASONS`.
    """
    if info is None or isinstance(info, str):
        return False, "error"
    if not bool(_get(info, "success", False)):
        return False, "failed"
    d = _get(info, "d_l2", float("nan"))
    if d is None or not math.isfinite(float(d)) or float(d) > config.max_d_l2:
        return False, "d_l2"
    residual = _get(info, "residual", {}) or {}
    force = float(residual.get("force_mean_mg", 0.0))
    if not math.isfinite(force) or force > config.max_residual:
        return False, "residual"
    return True, "kept"
