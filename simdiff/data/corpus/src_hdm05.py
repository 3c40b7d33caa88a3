"""HDM05 cut takes (``shared/extra/hdm05/{train,test}/<class>/HDM_<actor>_<motion>_<take>_120.amc``
with per-actor ``HDM_<actor>.asf``), 120 fps, CC BY-SA 3.0. The class comes from the file name."""

from __future__ import annotations

import re
from pathlib import Path

from simdiff.data.corpus.archive import source_dir
from simdiff.data.corpus.item import Item

CLASSES: dict[str, tuple[str, tuple[str, ...]]] = {
    "depositFloorR": ("other", ("bends down and puts something on the floor with the right hand",
                                "places an object on the floor with the right hand")),
    "squat1Reps": ("exercise", ("does a squat", "squats down and stands back up")),
    "throwBasketball": ("sports", ("throws a basketball", "shoots a basketball with both hands")),
    "elbowToKnee1RepsLelbowStart": ("exercise", ("touches each elbow to the opposite knee",
                                                 "does an elbow-to-knee exercise")),
    "grabHighR": ("other", ("reaches up high and grabs something with the right hand",
                            "grabs an object from a high place with the right hand")),
    "hopBothLegs1hops": ("jump", ("hops forward on both legs", "jumps forward with both feet together")),
    "jogLeftCircle4StepsRstart": ("run", ("jogs in a circle to the left", "jogs around a left-hand curve")),
    "kickLFront1Reps": ("sports", ("kicks to the front with the left leg", "does a front kick with the left foot")),
    "lieDownFloor": ("ground", ("lies down on the floor", "gets down and lies on the floor")),
    "rotateArmsBothBackward1Reps": ("exercise", ("rotates both arms backward", "circles both arms backwards")),
    "sneak2StepsLStart": ("walk", ("sneaks forward a few steps", "tiptoes forward quietly")),
}
"""HDM05 motion class (file name) -> (motion type, verb phrases)."""

_NAME = re.compile(r"^HDM_([a-z]+)_(.+)_(\d+)_(\d+)$")


def _fallback(motion: str) -> tuple[str, tuple[str, ...]]:
    words = re.sub(r"(?<=[a-z])(?=[A-Z0-9])", " ", motion).lower()
    return "other", (f"performs a {words} motion", f"does a {words}")


def discover(shared: Path, cache: Path) -> list[Item]:
    """One item per HDM05 AMC with its actor's ASF beside it."""
    root = source_dir(shared, cache, "hdm05")
    if root is None:
        return []
    items: list[Item] = []
    for path in sorted(root.glob("*/*/*.amc")):
        match = _NAME.match(path.stem)
        asf = path.parent / f"HDM_{match.group(1)}.asf" if match else None
        if match is None or asf is None or not asf.is_file():
            continue
        actor, motion, take, rate = match.groups()
        kind, verbs = CLASSES.get(motion, _fallback(motion))
        items.append(Item(
            id=f"hdm_{actor}_{motion}_{take}", trial=f"hdm05:{actor}/{motion}/{take}", source="hdm05",
            path=path, licence="CC-BY-SA-3.0", motion_type=kind, verbs=verbs, caption_origin="hdm05-class",
            description=motion, asf=asf, fps=float(rate),
        ))
    return items
