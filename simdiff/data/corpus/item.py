"""What a motion source hands the corpus builder: one :class:`Item` per take, plus the
motion types shared by every source (licence codes: :mod:`simdiff.licences`)."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from simdiff.errors import SimdiffError
from simdiff.licences import LICENCES

MOTION_TYPES: tuple[str, ...] = (
    "dance", "acrobatics", "sports", "exercise", "ground", "climb", "jump", "run", "walk", "gesture", "other",
)
"""Coarse motion categories of every source (CMU's classifier plus ``gesture``)."""


@dataclass
class Item:
    """One take of one source, before windowing.

    Attributes:
        id: clip id prefix, unique over the corpus ("02_01", "bn2_walk_normal_001"); clips
            are ``<id>_<k>`` and their mirrors ``M<id>_<k>``.
        trial: key of the captured take: splits group by it and copies of one capture share
            it ("cmu:02_01"); the registry keeps one item per key.
        source: source name ("cmu-amc", "bandai", ...).
        path: the motion file.
        licence: a key of :data:`LICENCES`.
        motion_type: one of :data:`MOTION_TYPES`.
        verbs, adverbs, subjects: caption material for :func:`.phrasing.sentences` (verb
            phrases, manners, subjects carrying the manner); empty for CMU trials, whose
            captions come per window from KIT-ML or the CMU description.
        caption_origin: where captions come from ("kitml", "cmu-description", "bandai-labels", ...).
        description: short label shown in reports (CMU description, "walk / happy", class name).
        rank: preference among copies of one trial (lower wins: AMC 0, ... DeepMimic last).
        asf: ASF skeleton of an AMC file.
        fps: frame rate to force (None: the file's own).
        meta: anything else a source's loader needs (JSON-friendly).
    """

    id: str
    trial: str
    source: str
    path: Path
    licence: str
    motion_type: str
    verbs: tuple[str, ...] = ()
    adverbs: tuple[str, ...] = ()
    subjects: tuple[str, ...] = ()
    caption_origin: str = ""
    description: str = ""
    rank: int = 0
    asf: Path | None = None
    fps: float | None = None
    meta: dict[str, object] = field(default_factory=dict)
    alternates: list[Item] = field(default_factory=list)

    def __post_init__(self) -> None:
        if self.licence not in LICENCES:
            raise SimdiffError(f"{self.path}: unknown licence {self.licence!r} (known: {', '.join(LICENCES)})")
        if self.motion_type not in MOTION_TYPES:
            raise SimdiffError(f"{self.path}: unknown motion type {self.motion_type!r}")

    def files(self) -> list[Path]:
        """Every file the item's output depends on."""
        return [self.path] + ([self.asf] if self.asf is not None else [])
