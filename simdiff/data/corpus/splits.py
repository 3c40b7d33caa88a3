"""Train/val/test by trial, stratified by source family and motion type.

A trial's windows and mirrors share its split. CMU trials with HumanML3D segments follow
HumanML3D (test > val > train, so no HumanML3D test motion is trained on). The other trials
are grouped into strata (source family, motion type); inside a stratum of at least
:data:`MIN_STRATUM` trials the first (seeded order) free trial goes to test, the next to val
(so jumps, runs and dances are in every split), the rest each to the split furthest below
its share of the stratum's duration (:data:`TARGETS`).
"""

from __future__ import annotations

import hashlib
from collections.abc import Mapping

SPLIT_NAMES: tuple[str, ...] = ("train", "val", "test")
TARGETS: dict[str, float] = {"train": 0.80, "val": 0.05, "test": 0.15}
"""HumanML3D's proportions (23,384 / 1,460 / 4,384 of 29,228 clips)."""

MIN_STRATUM: int = 3
"""Fewest trials a stratum needs before it is forced into test and val."""


def _order(trial: str, seed: int) -> str:
    return hashlib.sha256(f"{seed}:{trial}".encode()).hexdigest()


def assign_stratified(
    durations: Mapping[str, float],
    strata: Mapping[str, str],
    fixed: Mapping[str, str] | None = None,
    *,
    seed: int = 0,
    targets: Mapping[str, float] = TARGETS,
) -> dict[str, str]:
    """Split of every trial.

    Args:
        durations: trial -> seconds of original motion.
        strata: trial -> stratum label ("bandai/walk").
        fixed: trial -> split imposed (HumanML3D membership).
        seed: order of the free trials.
        targets: wanted share per split.
    Returns:
        trial -> "train" | "val" | "test".
    """
    fixed = dict(fixed or {})
    out: dict[str, str] = {t: s for t, s in fixed.items() if t in durations}
    groups: dict[str, list[str]] = {}
    for trial in durations:
        groups.setdefault(strata.get(trial, ""), []).append(trial)
    scale = sum(targets.values()) or 1.0
    for label in sorted(groups):
        members = groups[label]
        used = {name: 0.0 for name in SPLIT_NAMES}
        for trial in members:
            if trial in out:
                used[out[trial]] += durations[trial]
        free = sorted((t for t in members if t not in out), key=lambda t: _order(t, seed))
        total = float(sum(durations[t] for t in members)) or 1.0
        if len(members) >= MIN_STRATUM:
            for name in ("test", "val"):
                if free and not any(out.get(t) == name for t in members):
                    trial = free.pop(0)
                    out[trial] = name
                    used[name] += durations[trial]
        for trial in free:
            deficit = {name: targets[name] / scale * total - used[name] for name in SPLIT_NAMES}
            best = max(SPLIT_NAMES, key=lambda name: (deficit[name], -SPLIT_NAMES.index(name)))
            out[trial] = best
            used[best] += durations[trial]
    return out
