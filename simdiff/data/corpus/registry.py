"""The motion sources, licence filtering and deduplication of copies of one capture."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path

from simdiff.data.corpus import src_bandai, src_cmu, src_deepmimic, src_hdm05
from simdiff.data.corpus.item import Item
from simdiff.licences import LICENCE_SETS
from simdiff.errors import SimdiffError

SOURCES: dict[str, Callable[[Path, Path], list[Item]]] = {
    "cmu": src_cmu.discover,
    "bandai": src_bandai.discover,
    "hdm05": src_hdm05.discover,
    "deepmimic": src_deepmimic.discover,
}
"""Source family -> ``discover(shared_root, cache)``."""


def discover_all(shared: Path, cache: Path, sources: Sequence[str] | None = None, licence: str = "all") -> list[Item]:
    """Items of the chosen sources allowed by ``licence``, one per trial key, sorted by id.

    Copies of one trial (same key) keep the lowest ``rank``; the others become its
    ``alternates`` (cross-checks). Clip ids must be unique across the kept items.

    Raises:
        SimdiffError: unknown source or licence set, a missing shared folder, an id collision.
    """
    shared = Path(shared)
    if not shared.is_dir():
        raise SimdiffError(f"shared data folder not found: {shared}")
    chosen = list(sources) if sources else list(SOURCES)
    unknown = [s for s in chosen if s not in SOURCES]
    if unknown:
        raise SimdiffError(f"unknown source(s) {', '.join(unknown)}; choose from {', '.join(SOURCES)}")
    if licence not in LICENCE_SETS:
        raise SimdiffError(f"unknown licence set {licence!r}; choose from {', '.join(LICENCE_SETS)}")
    allowed = LICENCE_SETS[licence]
    found: list[Item] = []
    for name in chosen:
        found += [item for item in SOURCES[name](shared, cache) if item.licence in allowed]
    by_trial: dict[str, list[Item]] = {}
    for item in found:
        by_trial.setdefault(item.trial, []).append(item)
    kept: dict[str, Item] = {}
    for trial, copies in by_trial.items():
        copies.sort(key=lambda i: (i.rank, i.source, str(i.path)))
        best = copies[0]
        best.alternates = copies[1:]
        if best.id in kept:
            raise SimdiffError(f"clip id {best.id!r} used by {kept[best.id].path} and {best.path}")
        kept[best.id] = best
    return [kept[k] for k in sorted(kept)]
