"""DeepMimic clips (``shared/extra/deepmimic-xbpeng/data/motions``, MIT, and the named clips of
``shared/cmu/deepmimic/extra``), 30 fps JSON. Files with the same bytes are one item (hash);
``*_mirror`` files are left out (the corpus makes its own mirrors)."""

from __future__ import annotations

from pathlib import Path

from simdiff.data.corpus.archive import source_dir
from simdiff.data.corpus.item import Item
from simdiff.fsio import file_digest

NAMES: dict[str, tuple[str, tuple[str, ...]]] = {
    "backflip": ("acrobatics", ("does a backflip", "flips backwards in the air")),
    "sideflip": ("acrobatics", ("does a side flip", "flips sideways in the air")),
    "cartwheel": ("acrobatics", ("does a cartwheel", "turns a cartwheel")),
    "roll": ("acrobatics", ("does a forward roll", "rolls forward on the ground")),
    "run_roll": ("acrobatics", ("runs and dives into a roll", "runs forward and rolls")),
    "bridge": ("acrobatics", ("bends backwards into a bridge", "does a back bridge")),
    "spinkick": ("sports", ("does a spinning kick", "spins around and kicks")),
    "kick": ("sports", ("kicks", "does a high kick")),
    "punch": ("sports", ("throws a punch", "punches forward")),
    "jump": ("jump", ("jumps", "jumps forward")),
    "run_jump": ("jump", ("runs and jumps", "runs forward and leaps")),
    "run": ("run", ("runs", "runs forward")),
    "jog": ("run", ("jogs", "jogs forward")),
    "walk": ("walk", ("walks", "walks forward")),
    "stealthy_walk": ("walk", ("sneaks forward", "walks stealthily")),
    "zombie_walk": ("walk", ("walks like a zombie", "shambles forward like a zombie")),
    "long_zombie": ("walk", ("walks like a zombie", "shambles forward like a zombie")),
    "crawl": ("ground", ("crawls on hands and knees", "crawls forward")),
    "getup_facedown": ("ground", ("gets up from lying face down", "stands up from the floor")),
    "getup_faceup": ("ground", ("gets up from lying on the back", "stands up from lying face up")),
    "dance_a": ("dance", ("dances", "does a dance")),
    "dance_b": ("dance", ("dances", "performs a dance")),
    "dance_spin": ("dance", ("dances and spins", "spins around while dancing")),
    "spin": ("dance", ("spins around", "turns around on the spot")),
}
"""Clip name (``humanoid3d_<name>`` without trailing digits) -> (motion type, verb phrases)."""


def _name(stem: str) -> str:
    return stem.removeprefix("humanoid3d_").rstrip("0123456789")


def discover(shared: Path, cache: Path) -> list[Item]:
    """One item per distinct DeepMimic clip file."""
    folders: list[Path] = []
    root = source_dir(shared, cache, "deepmimic-xbpeng")
    if root is not None:
        folders += [root / "data" / "motions", root / "data" / "motions" / "long"]
    folders.append(shared / "cmu" / "deepmimic" / "extra")
    items: list[Item] = []
    seen: dict[str, str] = {}
    for folder in folders:
        for path in sorted(folder.glob("humanoid3d_*.txt")):
            if path.stem.endswith("_mirror"):
                continue
            digest = file_digest([path])
            if digest in seen:
                continue
            stem = path.stem.removeprefix("humanoid3d_")
            clip = f"dm_{stem}"
            if clip in seen.values():
                clip = f"{clip}_{digest[:6]}"
            seen[digest] = clip
            kind, verbs = NAMES.get(_name(path.stem), ("other", (f"performs a {stem.replace('_', ' ')} motion",
                                                                  f"does a {stem.replace('_', ' ')}")))
            items.append(Item(
                id=clip, trial=f"deepmimic:{digest[:12]}", source="deepmimic", path=path, licence="MIT",
                motion_type=kind, verbs=verbs, caption_origin="deepmimic-name", description=stem,
                meta={"sha1": digest},
            ))
    return items
