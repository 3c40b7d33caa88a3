"""Intervals for reported numbers: Student-t over replications, a seeded cluster bootstrap.

Every table of ``simdiff evaluate`` (``reports/<name>/``) states a mean with a 95 % interval. With R replications
(R ≥ 5 in the ``full`` budgets) the normal-theory ``1.96·σ/√R`` of MDM understates the
uncertainty; we use the Student-t half-width ``t_{0.975, R−1} · s / √R`` with the sample
standard deviation ``s`` (ddof = 1).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
from scipy import stats as sps

from simdiff.errors import SimdiffError

CONFIDENCE: float = 0.95


def t_interval(values: Sequence[float] | np.ndarray, confidence: float = CONFIDENCE) -> tuple[float, float]:
    """(mean, half-width) of the Student-t interval of the mean of ``values``.

    Args:
        values: R ≥ 1 finite numbers (one per replication).
        confidence: two-sided level in (0, 1).
    Returns:
        (mean, ``t.ppf((1+confidence)/2, R−1)·s/√R``); the half-width is NaN for R = 1 (no spread known).
    """
    v = np.asarray(values, dtype=np.float64).reshape(-1)
    if v.size == 0:
        raise SimdiffError("no values to summarise")
    if not 0.0 < confidence < 1.0:
        raise SimdiffError(f"confidence must be in (0, 1), got {confidence}")
    if not np.all(np.isfinite(v)):
        raise SimdiffError(f"cannot summarise non-finite values: {v[~np.isfinite(v)][:3].tolist()}")
    if v.size == 1:
        return float(v[0]), float("nan")
    half = sps.t.ppf((1.0 + confidence) / 2.0, v.size - 1) * v.std(ddof=1) / np.sqrt(v.size)
    return float(v.mean()), float(half)


def bootstrap_interval(units: Sequence[object], statistic: Callable[[list[object]], float], *, resamples: int = 1000,
                       seed: int = 0, confidence: float = CONFIDENCE) -> tuple[float, float, float]:
    """(estimate, low, high): percentile bootstrap over independent ``units`` (resampled with replacement).

    Args:
        units: the independent units (e.g. one (prompt, seed) motion with all its φ).
        statistic: list of units → number (NaN when undefined; such resamples are skipped).
        resamples: bootstrap draws; seed: makes the interval reproducible.
    """
    items = list(units)
    if not items:
        raise SimdiffError("bootstrap needs at least one unit")
    est = float(statistic(items))
    rng = np.random.default_rng(seed)
    draws = []
    for _ in range(resamples):
        pick = rng.integers(0, len(items), len(items))
        value = statistic([items[i] for i in pick])
        if np.isfinite(value):
            draws.append(value)
    if not draws:
        return est, float("nan"), float("nan")
    tail = (1.0 - confidence) / 2.0 * 100.0
    lo, hi = np.percentile(draws, [tail, 100.0 - tail])
    return est, float(lo), float(hi)


def wilson_interval(passed: int, n: int, confidence: float = CONFIDENCE) -> tuple[float, float]:
    """(low, high) Wilson score interval of a pass rate ``passed``/``n`` (n ≥ 1); stays inside [0, 1] and is not
    empty at 0 or n passes, unlike the normal approximation."""
    if n < 1 or not 0 <= passed <= n:
        raise SimdiffError(f"a pass rate needs 0 <= passed <= n and n >= 1, got {passed}/{n}")
    z = float(sps.norm.ppf((1.0 + confidence) / 2.0))
    p = passed / n
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z * np.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    return float(max(0.0, centre - half)), float(min(1.0, centre + half))
