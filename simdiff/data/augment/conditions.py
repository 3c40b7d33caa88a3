"""The environments φ a corpus is replayed under (SimDiff §5.1, Appendix D).

* ``binary``: one condition, Earth gravity without wind (−9.81, 0, 0).
* ``random``: ``n`` conditions (paper: 30), one factor at a time, balanced over the three
  factors in the order gravity, wind_x, wind_y, gravity, …:
  gravity ``g_z ~ U[−20, −1]`` m/s² with no wind, or wind ``w_x ~ U[−10, 10]`` N or
  ``w_y ~ U[−10, 10]`` N at Earth gravity. The same ``n`` conditions are applied to every
  clip, so the kept fraction per condition is comparable across clips.
* ``paper``: the paper's full grid: every clip under all ``n`` (30) random conditions.
* ``paired`` (default): every clip at Earth (index 0) and under ``k`` conditions of its own
  (indices 1..k), drawn one factor at a time from a generator seeded by (seed, clip id) and
  nothing else, so φ is independent of the clip's content; the factors cycle gravity,
  wind_x, wind_y from a per-clip random start (k = 6 gives each factor twice). Each clip's
  Earth rollout is the baseline its physics signal is measured against. ``factors`` and
  ``gravity_range`` narrow the draw (e.g. gravity only, g_z in [−5, −1] for a weak-gravity run);
  the defaults draw exactly as before.
"""

from __future__ import annotations

import zlib
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from simdiff.errors import SimdiffError
from simdiff.sim.env import EARTH_GRAVITY, GRAVITY_RANGE, MAX_WIND, Environment

MODES: tuple[str, ...] = ("binary", "random", "paper", "paired")
DEFAULT_PAIRED_K: int = 6
"""Conditions drawn per clip in paired mode (besides Earth)."""
FACTORS: tuple[str, ...] = ("gravity", "wind_x", "wind_y")


@dataclass(frozen=True)
class AugmentEnv:
    """One environment of the augmentation.

    Attributes:
        index: position in the condition list (the categorical ``env_index`` in random mode).
        factor: ``earth``, ``gravity``, ``wind_x`` or ``wind_y`` (the factor that was drawn).
        env: φ = (g_z m/s², w_x N, w_y N).
    """

    index: int
    factor: str
    env: Environment

    def to_dict(self) -> dict:
        return {"index": self.index, "factor": self.factor, "env": list(self.env.as_tuple())}

    @classmethod
    def from_dict(cls, data: dict) -> "AugmentEnv":
        return cls(int(data["index"]), str(data["factor"]), Environment(*map(float, data["env"])))


def binary_conditions() -> list[AugmentEnv]:
    """The single Earth condition of the binary setting."""
    return [AugmentEnv(0, "earth", Environment(EARTH_GRAVITY, 0.0, 0.0))]


def random_conditions(n: int = 30, seed: int = 0) -> list[AugmentEnv]:
    """``n`` one-factor-at-a-time environments, deterministic under ``seed`` (values rounded to 1e-4)."""
    if n < 1:
        raise SimdiffError(f"--conditions must be at least 1, got {n}")
    rng = np.random.default_rng([seed, 0xA06])
    lo, hi = GRAVITY_RANGE
    out: list[AugmentEnv] = []
    for i in range(n):
        factor = FACTORS[i % 3]
        if factor == "gravity":
            env = Environment(round(float(rng.uniform(lo, hi)), 4), 0.0, 0.0)
        elif factor == "wind_x":
            env = Environment(EARTH_GRAVITY, round(float(rng.uniform(-MAX_WIND, MAX_WIND)), 4), 0.0)
        else:
            env = Environment(EARTH_GRAVITY, 0.0, round(float(rng.uniform(-MAX_WIND, MAX_WIND)), 4))
        out.append(AugmentEnv(i, factor, env.validate()))
    return out


def _draw(rng: np.random.Generator, factor: str,
          gravity_range: tuple[float, float] = GRAVITY_RANGE) -> Environment:
    lo, hi = gravity_range
    if factor == "gravity":
        return Environment(round(float(rng.uniform(lo, hi)), 4), 0.0, 0.0)
    w = round(float(rng.uniform(-MAX_WIND, MAX_WIND)), 4)
    return Environment(EARTH_GRAVITY, w, 0.0) if factor == "wind_x" else Environment(EARTH_GRAVITY, 0.0, w)


def check_factors(factors: Sequence[str]) -> tuple[str, ...]:
    """``factors`` as a tuple in :data:`FACTORS` order; a one-line error names an unknown or repeated one."""
    factors = tuple(factors)
    if not factors:
        raise SimdiffError("--factors: name at least one of " + ", ".join(FACTORS))
    for f in factors:
        if f not in FACTORS:
            raise SimdiffError(f"--factors: unknown factor {f!r}; choose from {', '.join(FACTORS)}")
    if len(set(factors)) != len(factors):
        raise SimdiffError(f"--factors: {', '.join(factors)} names a factor twice")
    return tuple(f for f in FACTORS if f in factors)


def check_gravity_range(gravity_range: Sequence[float]) -> tuple[float, float]:
    """``(lo, hi)`` m/s² within :data:`GRAVITY_RANGE` with lo <= hi (lo == hi: that one gravity), else a one-line
    error naming it."""
    lo, hi = (float(v) for v in gravity_range)
    glo, ghi = GRAVITY_RANGE
    if not (np.isfinite(lo) and np.isfinite(hi)) or not glo <= lo <= hi <= ghi:
        raise SimdiffError(f"--gravity-range {lo:g} {hi:g}: need {glo:g} <= LO <= HI <= {ghi:g} "
                           "(m/s^2, negative = down)")
    return lo, hi


def check_one_gravity(k: int, factors: Sequence[str], gravity_range: Sequence[float]) -> None:
    """A one-gravity range (lo == hi) with more paired draws ``k`` than ``factors`` would simulate a clip under the same
    gravity more than once: a one-line error naming it."""
    lo, hi = gravity_range
    if lo == hi and "gravity" in factors and k > len(factors):
        raise SimdiffError(f"--gravity-range {lo:g} {hi:g} is one gravity: with --conditions {k} over {len(factors)} "
                           f"factor(s) a clip would be simulated under it more than once; use --conditions "
                           f"{len(factors)} or a range")


def paired_conditions(clip: str, k: int = DEFAULT_PAIRED_K, seed: int = 0, factors: Sequence[str] = FACTORS,
                      gravity_range: Sequence[float] = GRAVITY_RANGE) -> list[AugmentEnv]:
    """Earth and ``k`` one-factor conditions of one clip, seeded by (seed, clip id) only.

    Args:
        clip: the clip id (its bytes seed the draw, through CRC-32; its content never does).
        k: conditions besides Earth.
        seed: run seed.
        factors: the factors drawn, cycled from a per-clip random start (default all three).
        gravity_range: ``(lo, hi)`` of the uniform g_z draw, m/s² (default the validated range; lo == hi: that
            gravity, then at most one draw per factor).
    Returns:
        ``[Earth (index 0), draw 1, …, draw k]``, values rounded to 1e-4.
    """
    if k < 1:
        raise SimdiffError(f"--conditions must be at least 1 in paired mode, got {k}")
    factors = check_factors(factors)
    gravity_range = check_gravity_range(gravity_range)
    check_one_gravity(k, factors, gravity_range)
    rng = np.random.default_rng([seed, 0xA13, zlib.crc32(clip.encode("utf-8"))])
    start = int(rng.integers(3))
    out = [AugmentEnv(0, "earth", Environment(EARTH_GRAVITY, 0.0, 0.0))]
    for i in range(k):
        factor = factors[(start + i) % len(factors)]
        out.append(AugmentEnv(i + 1, factor, _draw(rng, factor, gravity_range).validate()))
    return out


def make_conditions(mode: str, n: int = 30, seed: int = 0) -> list[AugmentEnv]:
    """The shared condition list of ``mode`` (``binary`` ignores ``n`` and ``seed``; ``paired``
    draws per clip, see :func:`paired_conditions`, and returns the Earth condition here)."""
    if mode == "binary":
        return binary_conditions()
    if mode in ("random", "paper"):
        return random_conditions(n, seed)
    if mode == "paired":
        return binary_conditions()
    raise SimdiffError(f"unknown augmentation mode {mode!r}; choose one of {', '.join(MODES)}")
