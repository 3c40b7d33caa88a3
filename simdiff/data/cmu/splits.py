"""Train/val/test assignment by trial, deterministic, following HumanML3D where it can.

Rules, in order: a trial with any segment in HumanML3D's test split goes to test (so no
HumanML3D test motion is ever trained on); else one with a val segment goes to val; else
one with a train segment goes to train. The remaining trials are visited in a seeded order
and each goes to the split furthest below its target share of the corpus duration.
A trial's windows and their mirrors all share the trial's split.
"""

from __future__ import annotations

import hashlib
from collections.abc import Mapping

from simdiff.errors import SimdiffError

SPLIT_NAMES: tuple[str, ...] = ("train", "val", "test")
TARGETS: dict[str, float] = {"train": 0.80, "val": 0.05, "test": 0.15}
"""HumanML3D's proportions (23,384 / 1,460 / 4,384 of 29,228 clips)."""


def _order_key(trial: str, seed: int) -> str:
    return hashlib.sha256(f"{seed}:{trial}".encode()).hexdigest()


def assign_splits(
    durations: Mapping[str, float],
    hml3d: Mapping[str, set[str]],
    *,
    seed: int = 0,
    targets: Mapping[str, float] = TARGETS,
) -> dict[str, str]:
    """Split of every trial.

    Args:
        durations: trial -> seconds of motion it contributes (weights the balance).
        hml3d: trial -> HumanML3D splits its segments are in (empty when none).
        seed: orders the free trials.
        targets: wanted share of the total duration per split.
    Returns:
        trial -> "train" | "val" | "test".
    """
    if set(targets) != set(SPLIT_NAMES) or any(v < 0 for v in targets.values()):
        raise SimdiffError(f"split targets must give train/val/test shares, got {dict(targets)}")
    out: dict[str, str] = {}
    used = {name: 0.0 for name in SPLIT_NAMES}
    free: list[str] = []
    for trial, seconds in durations.items():
        labels = hml3d.get(trial, set())
        fixed = next((name for name in ("test", "val", "train") if name in labels), None)
        if fixed is None:
            free.append(trial)
        else:
            out[trial] = fixed
            used[fixed] += seconds
    total = float(sum(durations.values())) or 1.0
    scale = sum(targets.values()) or 1.0
    for trial in sorted(free, key=lambda t: _order_key(t, seed)):
        deficit = {name: targets[name] / scale * total - used[name] for name in SPLIT_NAMES}
        best = max(SPLIT_NAMES, key=lambda name: (deficit[name], -SPLIT_NAMES.index(name)))
        out[trial] = best
        used[best] += durations[trial]
    return out
