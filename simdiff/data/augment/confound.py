"""The confound check: φ must not predict the clip it was applied to.

Over the kept pairs, the Pearson correlation between each φ component (g_z, w_x, w_y) and
each descriptor of the source clip's content:

* ``speed``: mean horizontal root speed of the source (m/s);
* ``flight_s``: total airborne time of the source (s);
* ``type:<t>``: indicator of the motion type (``flight`` if the source has a flight of at
  least 0.1 s, else ``locomotion`` above 0.5 m/s, else ``static``);
* ``source:<s>``: indicator of the source group (the clip id's prefix before ``_``, e.g. the
  CMU subject; the ``max_groups`` most frequent groups, the rest pooled as ``other``).

An indicator with one value only (no variance) has no correlation and is left out. The check
passes when every |r| ≤ ``bound`` (the quality checks use 0.1).
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Sequence
from typing import Any

import numpy as np

PHI: tuple[str, ...] = ("g_z", "w_x", "w_y")


def motion_type(content: dict[str, float]) -> str:
    """``flight``, ``locomotion`` or ``static`` from :func:`simdiff.data.augment.signal.measure`."""
    if content.get("flight_s", 0.0) >= 0.1:
        return "flight"
    return "locomotion" if content.get("speed", 0.0) > 0.5 else "static"


def source_group(clip: str) -> str:
    """The clip id's prefix before the first ``_`` (the CMU subject of ``16_05``)."""
    return clip.split("_", 1)[0]


def _r(x: np.ndarray, y: np.ndarray) -> float | None:
    if len(x) < 3 or np.std(x) == 0 or np.std(y) == 0:
        return None
    return float(np.corrcoef(x, y)[0, 1])


def confound_check(pairs: Sequence[dict[str, Any]], content: dict[str, dict[str, float]], bound: float = 0.1,
                   max_groups: int = 8) -> dict[str, Any]:
    """Correlations between φ and clip content over the given (kept) pairs.

    Args:
        pairs: one per kept pair with ``clip`` and ``env`` (g_z, w_x, w_y).
        content: per clip id, :func:`simdiff.data.augment.signal.measure` of its source.
        bound: largest |r| that passes.
        max_groups: source groups kept as separate indicators.
    Returns:
        {"r": {phi: {descriptor: r}}, "max_abs_r", "worst": (phi, descriptor), "passes", "pairs"}.
    """
    rows = [p for p in pairs if p["clip"] in content]
    out: dict[str, Any] = {"r": {k: {} for k in PHI}, "max_abs_r": None, "worst": None, "passes": None,
                           "pairs": len(rows), "bound": bound}
    if len(rows) < 3:
        return out
    phi = np.array([[float(v) for v in p["env"]] for p in rows])
    cols: dict[str, np.ndarray] = {
        "speed": np.array([content[p["clip"]].get("speed", 0.0) for p in rows]),
        "flight_s": np.array([content[p["clip"]].get("flight_total_s", 0.0) for p in rows]),
    }
    types = [motion_type(content[p["clip"]]) for p in rows]
    for t in sorted(set(types)):
        cols[f"type:{t}"] = np.array([x == t for x in types], dtype=float)
    groups = [source_group(p["clip"]) for p in rows]
    top = {g for g, _ in Counter(groups).most_common(max_groups)}
    groups = [g if g in top else "other" for g in groups]
    for g in sorted(set(groups)):
        cols[f"source:{g}"] = np.array([x == g for x in groups], dtype=float)
    worst, best = None, -1.0
    for i, name in enumerate(PHI):
        for desc, y in cols.items():
            r = _r(phi[:, i], y)
            if r is None:
                continue
            out["r"][name][desc] = r
            if abs(r) > best:
                best, worst = abs(r), (name, desc)
    if worst is not None:
        out.update(max_abs_r=best, worst=list(worst), passes=best <= bound)
    return out
