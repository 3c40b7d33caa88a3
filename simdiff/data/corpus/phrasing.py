"""Captions for sources without human text: a few natural sentences per take.

Every source gives verb phrases ("walks to the left") and, optionally, a manner as an
adverbial ("energetically") and as a subject ("an energetic person"); :func:`sentences`
combines them into >= 2 distinct sentences, deterministic in (seed, key).
"""

from __future__ import annotations

import hashlib
import random
from collections.abc import Sequence

SUBJECTS: tuple[str, ...] = ("a person", "someone", "a person", "the person", "a human")
"""Sentence subjects; "a person" weighted double, as in HumanML3D."""


def _rng(key: str, seed: int) -> random.Random:
    digest = hashlib.sha256(f"{seed}:{key}".encode()).digest()
    return random.Random(int.from_bytes(digest[:8], "little"))


def sentences(
    verbs: Sequence[str],
    *,
    adverbs: Sequence[str] = (),
    subjects: Sequence[str] = (),
    n: int = 3,
    seed: int = 0,
    key: str = "",
) -> list[str]:
    """Up to ``n`` distinct lower-case sentences ending in a full stop (at least 2 when the
    inputs allow it; one verb phrase alone still gives 2 by varying the subject).

    Args:
        verbs: alternative verb phrases, third person ("walks forward"); the first is the plain one.
        adverbs: alternative manners placed after the verb ("happily", "like an elderly person").
        subjects: alternative subjects carrying the manner ("an elderly person").
        n: sentences wanted.
        seed, key: make the choice deterministic and different per take.
    """
    if not verbs:
        raise ValueError("sentences() needs at least one verb phrase")
    rng = _rng(key, seed)
    out: list[str] = []

    def add(text: str) -> None:
        text = " ".join(text.split()).strip()
        if text and text not in out:
            out.append(text)

    add(f"{SUBJECTS[0]} {verbs[0]}{' ' + adverbs[0] if adverbs else ''}.")
    for attempt in range(8 * n):
        if len(out) >= n:
            break
        verb = verbs[(attempt + 1 + rng.randrange(len(verbs))) % len(verbs)]
        form = (attempt + rng.randrange(3)) % 3
        if form == 0 and subjects:
            add(f"{subjects[rng.randrange(len(subjects))]} {verb}.")
        elif form == 1 and adverbs:
            add(f"{SUBJECTS[rng.randrange(len(SUBJECTS))]} {verb} {adverbs[rng.randrange(len(adverbs))]}.")
        else:
            manner = f" {adverbs[rng.randrange(len(adverbs))]}" if adverbs else ""
            add(f"{SUBJECTS[rng.randrange(len(SUBJECTS))]} {verb}{manner}.")
    return out[:n]
