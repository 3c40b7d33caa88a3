"""The keep decision at finalize: a pure function of the shard records and a :class:`FilterConfig`.

The driver writes the files of every tracked pair (``written``); which of them enter the
corpus is decided here, when the run finalises, so changing only the thresholds and running
the same command again re-finalises without simulating.

``max_pose_d_l2 = "auto"`` calibrates the pose threshold on the run's own Earth pairs: the
smallest value at which the Earth keep rate (kept Earth pairs / all Earth pairs, every
criterion applied) reaches ``earth_keep`` (default 0.66, the Earth keep rate of a filter
without the flight clock, d_L2 ≤ 7 and residual ≤ 0.1·m·|g_z|). When fewer Earth pairs than that tracked with an
acceptable residual, the target is unreachable and the threshold is the largest pose d_L2
among those pairs (every tracked, residual-ok Earth pair is kept). Pairs derived from a
mirror (``mirrored_from``) do not enter the calibration and follow their original's decision.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from typing import Any

from simdiff.data.augment.filter import AUTO, FilterConfig, keep_pair, rejections
from simdiff.errors import SimdiffError
from simdiff.sim.env import EARTH_GRAVITY


def is_earth(record: dict[str, Any]) -> bool:
    """True for a pair simulated at Earth gravity without wind (``env`` = (−9.81, 0, 0))."""
    env = record.get("env")
    return env is not None and list(map(float, env)) == [EARTH_GRAVITY, 0.0, 0.0]


def _errored(record: dict[str, Any]) -> bool:
    return record.get("reason") == "error" or record.get("info") is None or isinstance(record.get("info"), str)


def calibrate_pose_threshold(records: Sequence[dict[str, Any]], config: FilterConfig) -> dict[str, Any]:
    """Smallest pose d_L2 bound reaching ``config.earth_keep`` on the simulated Earth pairs.

    Returns:
        ``{"max_pose_d_l2", "earth_keep_target", "earth_pairs", "reachable"}`` (threshold in
        normalised feature units).
    """
    target = float(config.earth_keep)
    if not 0.0 < target <= 1.0:
        raise SimdiffError(f"--earth-keep must be in (0, 1], got {target}")
    earth = [r for r in records if is_earth(r) and not r.get("mirrored_from")]
    if not earth:
        raise SimdiffError("--max-pose-d-l2 auto needs Earth pairs in the run (none found); give a number")
    other = dataclasses.replace(config, max_pose_d_l2=None)
    values = sorted(float(r["info"]["d_l2_pose"]) for r in earth
                    if not _errored(r) and r.get("written", True) and not any(rejections(r["info"], other).values())
                    and r["info"].get("d_l2_pose") is not None and math.isfinite(float(r["info"]["d_l2_pose"])))
    need = max(1, math.ceil(target * len(earth) - 1e-9))
    reachable = len(values) >= need
    threshold = values[need - 1] if reachable else (values[-1] if values else 0.0)
    return {"max_pose_d_l2": threshold, "earth_keep_target": target, "earth_pairs": len(earth), "reachable": reachable}


def decide(records: Sequence[dict[str, Any]], config: FilterConfig) -> tuple[list[dict[str, Any]], dict[str, Any]]:
    """Apply the filter to shard records.

    Args:
        records: shard records (``id``, ``info``, ``written``; ``reason`` "error" for errors;
            ``mirrored_from`` for derived pairs).
        config: thresholds; ``max_pose_d_l2 = "auto"`` is calibrated first.
    Returns:
        (records with ``kept`` and ``reason`` set, filter summary: the thresholds used and,
        for auto, the calibration with the achieved Earth keep rate).
    """
    calibration = None
    if config.max_pose_d_l2 == AUTO:
        calibration = calibrate_pose_threshold(records, config)
        config = dataclasses.replace(config, max_pose_d_l2=calibration["max_pose_d_l2"])
    elif isinstance(config.max_pose_d_l2, str):
        raise SimdiffError(f"max_pose_d_l2 must be a number or 'auto', got {config.max_pose_d_l2!r}")
    decided: dict[str, tuple[bool, str]] = {}
    out = []
    for r in records:  # originals come before their mirrors within a shard
        if _errored(r):
            kept, reason = False, "error"
        elif r.get("mirrored_from") in decided:
            kept, reason = decided[r["mirrored_from"]]
        else:
            kept, reason = keep_pair(r["info"], config)
            # shards of older runs wrote only the pairs they kept (no "written" field)
            if kept and not r.get("written", r.get("kept", False)):
                kept, reason = False, "failed"
        decided[r["id"]] = (kept, reason)
        out.append({**r, "kept": kept, "reason": reason})
    summary: dict[str, Any] = {"thresholds": dataclasses.asdict(config)}
    if calibration is not None:
        earth = [r for r in out if is_earth(r) and not r.get("mirrored_from")]
        calibration["earth_kept"] = sum(r["kept"] for r in earth)
        calibration["earth_keep_achieved"] = calibration["earth_kept"] / len(earth)
        summary["calibration"] = calibration
    return out, summary
