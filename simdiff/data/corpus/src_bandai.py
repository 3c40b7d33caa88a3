"""Bandai-Namco Research Motion dataset (``shared/extra/bandai-namco``): 30 fps BVH in
centimetres on a 22-joint game rig, CC BY-NC 4.0. Each ``data/*.bvh`` has a ``*.json``
``{"content": i, "style": j}`` indexing ``cfg/content_label.txt`` / ``cfg/style_label.txt``;
captions combine the content ("walks to the left") and the style ("like an elderly person")."""

from __future__ import annotations

import json
from pathlib import Path

from simdiff.data.corpus.archive import source_dir
from simdiff.data.corpus.item import Item

CONTENTS: dict[str, tuple[str, tuple[str, ...]]] = {
    "walk": ("walk", ("walks forward", "walks ahead", "takes a walk forward")),
    "run": ("run", ("runs forward", "jogs ahead", "runs")),
    "dash": ("run", ("dashes forward", "sprints ahead", "runs fast")),
    "walk-back": ("walk", ("walks backward", "steps backwards", "walks backwards")),
    "walk-left": ("walk", ("walks to the left", "steps sideways to the left", "moves to the left")),
    "walk-right": ("walk", ("walks to the right", "steps sideways to the right", "moves to the right")),
    "walk-turn-left": ("walk", ("walks and turns left", "turns to the left while walking")),
    "walk-turn-right": ("walk", ("walks and turns right", "turns to the right while walking")),
    "bow": ("gesture", ("bows", "takes a bow", "bows politely")),
    "bye": ("gesture", ("waves goodbye", "says goodbye with a wave of the hand")),
    "byebye": ("gesture", ("waves goodbye", "waves bye-bye with a hand")),
    "guide": ("gesture", ("shows the way with a hand", "gestures as if guiding someone")),
    "respond": ("gesture", ("responds with a gesture", "reacts to someone with a gesture")),
    "call": ("gesture", ("beckons someone over", "calls someone over with a hand")),
    "punch": ("sports", ("throws punches", "punches forward", "throws a punch")),
    "kick": ("sports", ("kicks", "kicks forward", "does a kick")),
    "slash": ("sports", ("slashes with a sword", "swings a blade", "slashes as if with a sword")),
    "dance-long": ("dance", ("dances", "performs a dance", "dances for a while")),
    "dance-short": ("dance", ("dances", "does a short dance", "performs a short dance")),
    "wave-both-hands": ("gesture", ("waves both hands", "waves with both hands")),
    "wave-left-hand": ("gesture", ("waves the left hand", "waves with the left hand")),
    "wave-right-hand": ("gesture", ("waves the right hand", "waves with the right hand")),
    "raise-up-both-hands": ("gesture", ("raises both hands", "lifts both hands up")),
    "raise-up-left-hand": ("gesture", ("raises the left hand", "lifts the left hand up")),
    "raise-up-right-hand": ("gesture", ("raises the right hand", "lifts the right hand up")),
}
"""Content label -> (motion type, verb phrases)."""

STYLES: dict[str, tuple[tuple[str, ...], tuple[str, ...]]] = {
    "normal": ((), ()),
    "happy": (("happily", "in a happy mood"), ("a happy person", "a cheerful person")),
    "sad": (("sadly", "in a sad way"), ("a sad person", "an unhappy person")),
    "angry": (("angrily", "in an angry way"), ("an angry person", "an annoyed person")),
    "proud": (("proudly", "with pride"), ("a proud person",)),
    "not-confident": (("timidly", "without confidence"), ("an unsure person", "a shy person")),
    "masculinity": (("in a masculine way",), ("a man",)),
    "masculine": (("in a masculine way",), ("a man",)),
    "feminine": (("in a feminine way", "gracefully"), ("a woman",)),
    "childish": (("like a child", "in a childish way"), ("a child", "a playful child")),
    "old": (("like an old person", "slowly like an elderly person"), ("an elderly person", "an old person")),
    "elderly": (("like an elderly person", "slowly like an old person"), ("an elderly person", "an old person")),
    "tired": (("wearily", "in a tired way"), ("a tired person", "an exhausted person")),
    "exhausted": (("wearily", "as if exhausted"), ("an exhausted person", "a tired person")),
    "active": (("energetically", "with lots of energy"), ("an energetic person", "a lively person")),
    "musical": (("theatrically, like in a musical", "in a musical style"), ("a performer in a musical",)),
    "giant": (("with heavy, giant-like movements", "like a giant"), ("a giant", "a huge heavy person")),
    "chimpira": (("like a thug", "with a thuggish swagger"), ("a thug", "a street punk")),
    "youthful": (("in a youthful way", "with youthful energy"), ("a young person", "a youthful person")),
}
"""Style label -> (manners after the verb, subjects carrying the manner)."""


def _labels(path: Path) -> list[str]:
    """Lines of a ``cfg/*_label.txt`` without the ``dataset-N_`` prefix."""
    if not path.is_file():
        return []
    return [line.strip().split("_", 1)[-1] for line in path.read_text(encoding="utf-8").splitlines() if line.strip()]


def discover(shared: Path, cache: Path) -> list[Item]:
    """One item per Bandai BVH whose content and style are known."""
    root = source_dir(shared, cache, "bandai-namco")
    if root is None:
        return []
    items: list[Item] = []
    for dataset in sorted((root / "dataset").glob("Bandai-Namco-Research-Motiondataset-*")):
        number = dataset.name.rsplit("-", 1)[-1]
        contents, styles = _labels(dataset / "cfg" / "content_label.txt"), _labels(dataset / "cfg" / "style_label.txt")
        for path in sorted((dataset / "data").glob("*.bvh")):
            try:
                label = json.loads(path.with_suffix(".json").read_text())
                content, style = contents[int(label["content"])], styles[int(label["style"])]
            except (OSError, ValueError, KeyError, IndexError, TypeError):
                parts = path.stem.split("_")  # dataset-1_walk-left_happy_001
                if len(parts) != 4:
                    continue
                content, style = parts[1], parts[2]
            kind, verbs = CONTENTS.get(content, ("other", (f"performs a {content.replace('-', ' ')} motion",)))
            adverbs, subjects = STYLES.get(style, ((f"in a {style.replace('-', ' ')} style",), ()))
            take = path.stem.split("_")[-1]
            items.append(Item(
                id=f"bn{number}_{content}_{style}_{take}", trial=f"bandai:{number}/{path.stem}", source="bandai",
                path=path, licence="CC-BY-NC-4.0", motion_type=kind, verbs=verbs, adverbs=adverbs,
                subjects=subjects, caption_origin="bandai-labels", description=f"{content} / {style}",
            ))
    return items
