"""Sharing mirrors (``--share-mirrors``): derive the pairs of a mirrored clip ``M<id>`` from ``<id>``'s.

The MuJoCo humanoid and its tracker are left-right symmetric, so the rollout of the mirrored
clip under the mirrored environment is (up to numerics) the mirror of the original's rollout
(measured on 6 clips × 4 φ: 0.000 mm apart, the same success and length in 24 of 24 pairs).
Mirroring negates HumanML3D's X axis (the character's left at frame 0); wind ``w_x`` is the force along HumanML3D +X
(:mod:`simdiff.sim.env`: world y = HumanML3D x, ``gravity_vector`` = (w_y, w_x, g_z)/M), so
mirror(φ) = (g_z, −w_x, w_y). With sharing, ``M<id>``'s conditions are mirror(``<id>``'s)
rather than independent draws, and its rollouts are mirror(``<id>``'s rollouts).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from simdiff.data.augment.conditions import AugmentEnv
from simdiff.motion.mirror import mirror_joints
from simdiff.sim.env import Environment

MIRROR_PREFIX = "M"


def mirror_env(env: Environment) -> Environment:
    """mirror(φ) = (g_z, −w_x, w_y): the wind component along HumanML3D X flips, the rest stays."""
    return Environment(env.gravity, -env.wind_x + 0.0, env.wind_y)


def mirror_condition(cond: AugmentEnv) -> AugmentEnv:
    """The same condition index and factor under the mirrored environment."""
    return AugmentEnv(cond.index, cond.factor, mirror_env(cond.env))


def mirror_sources(clips: Sequence[str]) -> dict[str, str]:
    """{mirrored clip ``M<id>``: its original ``<id>``} for the pairs that are both in ``clips``."""
    present = set(clips)
    return {c: c[len(MIRROR_PREFIX):] for c in clips
            if c.startswith(MIRROR_PREFIX) and c[len(MIRROR_PREFIX):] in present}


def mirror_rollout(rollout: np.ndarray | None) -> np.ndarray | None:
    """(T, 22, 3) rollout joints mirrored (None stays None)."""
    return None if rollout is None else np.asarray(mirror_joints(np.asarray(rollout, dtype=np.float32)), dtype=np.float32)


def group_mirrors(clips: Sequence[str]) -> list[list[str]]:
    """The clips as units ``[<id>, M<id>]`` (both present) or ``[clip]``, in the order of ``<id>``.

    Shards are cut between units, so a mirrored clip is always in its original's shard.
    """
    sources = mirror_sources(clips)
    derived_of: dict[str, str] = {x: mx for mx, x in sources.items()}
    return [[c, derived_of[c]] if c in derived_of else [c] for c in clips if c not in sources]


def mirror_info(info: Any, env: Environment) -> Any:
    """The original pair's info for the mirrored pair: a copy with ``env`` set to mirror(φ).

    Every other field (success, d_L2, residual, CPU time) is the original rollout's; the
    rollout is the exact mirror, and the scalar metrics are mirror-invariant up to the
    normaliser's (small) left/right asymmetry.
    """
    if isinstance(info, dict):
        return {**info, "env": list(env.as_tuple())}
    return info
