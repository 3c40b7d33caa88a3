"""The environments φ a corpus is replayed under (SimDiff §5.1, Appendix D).

* ``binary``: one condition, Earth gravity without wind (−9.81, 0, 0).
* ``random``: ``n`` conditions (paper: 30), one factor at a time, balanced over the three
  factors in the order gravity, wind_x, wind_y, gravity, …:
  gravity ``g_z ~ U[−20, −1]`` m/s² with no wind, or wind ``w_x ~ U[−10, 10]`` N or
  ``w_y ~ U[−10, 10]`` N at Earth gravity. The same ``n`` conditions are applied to every
  clip, so the kept fraction per condition is comparable across clips.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from simdiff.errors import SimdiffError
from simdiff.sim.env import EARTH_GRAVITY, GRAVITY_RANGE, MAX_WIND, Environment

MODES: tuple[str, ...] = ("binary", "random")
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


def make_conditions(mode: str, n: int = 30, seed: int = 0) -> list[AugmentEnv]:
    """Conditions of ``mode`` (``binary`` ignores ``n`` and ``seed``)."""
    if mode == "binary":
        return binary_conditions()
    if mode == "random":
        return random_conditions(n, seed)
    raise SimdiffError(f"unknown augmentation mode {mode!r}; choose one of {', '.join(MODES)}")
