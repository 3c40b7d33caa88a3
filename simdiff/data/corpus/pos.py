"""A small rule-based lemmatiser and part-of-speech tagger for motion captions.

HumanML3D stores each caption with its tokens as ``lemma/TAG`` (Universal POS tags, as
spaCy gives them, punctuation dropped): "a man kicks with his left leg" ->
``a/DET man/NOUN kick/VERB with/ADP his/DET left/ADJ leg/NOUN``. This tagger reproduces
that format for the short, simple sentences of a motion corpus without a statistical
model: a closed-class lexicon (determiners, pronouns, prepositions, ...), a list of motion
verbs, a list of adjectives and adverbs, and suffix rules for the rest (default NOUN).
It is not a general-purpose tagger; its tags only feed the (optional) T2M evaluator.
"""

from __future__ import annotations

import re

_CLOSED: dict[str, str] = {}
for _tag, _words in {
    "DET": "a an the this that these those his her its their my your our each every some any "
    "both another either neither all no",
    "PRON": "he she it they them him i you we us me someone somebody something anyone anything "
    "itself himself herself themselves one",
    "ADP": "with in on at to from into onto over under around through across along up down "
    "of for by about behind towards toward off out before after above below between near "
    "like against underneath upon inside outside past",
    "CCONJ": "and or but",
    "SCONJ": "while as if because though although until when whilst",
    "AUX": "is are was were be been being has have had does do did can could will would may "
    "might should must",
    "PART": "not to 's",
    "ADV": "then ahead forward forwards backward backwards sideways slowly quickly again back away "
    "around very too also still briefly gently slightly fast high low together apart once "
    "twice repeatedly there here now afterwards first finally upward upwards downward "
    "downwards inward inwards outward outwards clockwise counterclockwise straight",
    "ADJ": "left right small big large fast slow quick brisk long short high low upright "
    "sad happy cool careful clumsy shy scared proud tired heavy light wide narrow straight "
    "uneven free full half sudden bad hurt injured other several few many little same "
    "sideways exaggerated stiff relaxed casual energetic angry depressed expressive "
    "outstretched raised bent lowered folded graceful confident sore strong deep",
    "NUM": "two three four five six seven eight nine ten eleven twelve",
}.items():
    for _w in _words.split():
        _CLOSED.setdefault(_w, _tag)

_VERBS: frozenset[str] = frozenset(
    """walk run jog jump hop skip leap step turn veer stop stand sit lie kneel crouch squat
    bend lean lift raise lower reach wave swing kick punch strike throw catch dribble shoot
    dance spin twirl whirl rotate twist climb crawl roll fall slip stumble trip get rise push
    pull carry pick grab hold dangle rock wash scrub move go come march limp stride shuffle
    sway circle cartwheel flip dive duck stretch balance bounce look perform do make take
    keep start begin end finish continue change switch return cross fold curl arch point
    extend tuck land scoop hang grip play fight block dodge brace wobble tiptoe sneak stomp
    swagger strut glide sprint dash pace wander stroll trudge drag hobble pivot bow shake
    clap flap drift veer strut mime pose scrub hunch slump""".split()
)
"""Lemmas treated as verbs (motion vocabulary)."""

_IRREGULAR: dict[str, str] = {
    "ran": "run", "running": "run", "runs": "run", "goes": "go", "went": "go", "gone": "go",
    "does": "do", "did": "do", "done": "do", "doing": "do", "has": "have", "had": "have",
    "is": "be", "are": "be", "was": "be", "were": "be", "been": "be", "being": "be",
    "gets": "get", "got": "get", "getting": "get", "sat": "sit", "sitting": "sit",
    "lies": "lie", "lying": "lie", "lay": "lie", "fell": "fall", "took": "take",
    "rose": "rise", "rising": "rise", "swung": "swing", "stood": "stand", "held": "hold",
    "threw": "throw", "caught": "catch", "made": "make", "came": "come", "knelt": "kneel",
    "leapt": "leap", "hung": "hang", "stopping": "stop",
    "hopping": "hop", "stepping": "step", "jogging": "jog", "skipping": "skip",
    "dribbling": "dribble", "swinging": "swing", "spinning": "spin", "slipping": "slip",
    "tripping": "trip", "dragging": "drag", "dropping": "drop", "flipping": "flip",
    "gripping": "grip", "clapping": "clap", "flapping": "flap", "stomping": "stomp",
}

_NOUN_IRREGULAR: dict[str, str] = {
    "men": "man", "women": "woman", "feet": "foot", "people": "person", "children": "child",
    "knees": "knee", "toes": "toe", "shoes": "shoe",
}

_WORD = re.compile(r"[A-Za-z]+(?:'[a-z]+)?|\d+(?:\.\d+)?")


def words(text: str) -> list[str]:
    """Lower-cased word tokens of ``text`` (punctuation dropped; digits kept)."""
    return [w.lower() for w in _WORD.findall(text.replace("-", " "))]


def _strip_verb(word: str) -> str | None:
    """Lemma of an inflected form of a known verb (walks, walking, walked), or None."""
    if word in _IRREGULAR:
        return _IRREGULAR[word]
    for suffix, repl in (("ies", "y"), ("ied", "y"), ("ying", "y"), ("es", ""), ("s", ""),
                         ("ing", ""), ("ing", "e"), ("ed", ""), ("ed", "e"), ("d", "")):
        if word.endswith(suffix) and len(word) > len(suffix) + 1:
            stem = word[: -len(suffix)] + repl
            if stem in _VERBS:
                return stem
            if len(stem) > 2 and stem[-1] == stem[-2] and stem[:-1] in _VERBS:
                return stem[:-1]  # stopped -> stop
    return None


def _singular(word: str) -> str:
    """Naive noun lemma: hands -> hand, knees -> knee, bodies -> body (not 'ss' words)."""
    if word in _NOUN_IRREGULAR:
        return _NOUN_IRREGULAR[word]
    if word.endswith("ies") and len(word) > 4:
        return word[:-3] + "y"
    if word.endswith(("ches", "shes", "xes", "sses")):
        return word[:-2]
    if word.endswith("s") and not word.endswith(("ss", "us", "is")) and len(word) > 3:
        return word[:-1]
    return word


def tag(text: str) -> list[tuple[str, str]]:
    """``(lemma, tag)`` for every word of a caption (Universal POS tags)."""
    out: list[tuple[str, str]] = []
    toks = words(text)
    for i, word in enumerate(toks):
        prev_tag = out[-1][1] if out else ""
        if word.isdigit() or re.fullmatch(r"\d+\.\d+", word):
            out.append((word, "NUM"))
            continue
        if word == "to":
            nxt = toks[i + 1] if i + 1 < len(toks) else ""
            out.append((word, "PART" if nxt in _VERBS else "ADP"))
            continue
        if word in ("left", "right"):
            nxt = toks[i + 1] if i + 1 < len(toks) else ""
            if prev_tag == "DET":
                side = "NOUN" if not nxt or nxt in _CLOSED else "ADJ"  # "to the left", "the left leg"
            else:
                side = "ADJ" if nxt and nxt not in _CLOSED else "ADV"  # "left leg", "veers left"
            out.append((word, side))
            continue
        if word in _NOUN_IRREGULAR:
            out.append((_NOUN_IRREGULAR[word], "NOUN"))
            continue
        if word in _CLOSED:
            closed = _CLOSED[word]
            if closed == "AUX":
                nxt = toks[i + 1] if i + 1 < len(toks) else ""
                main = nxt in _CLOSED and _CLOSED[nxt] in ("DET", "PRON", "NUM")
                out.append((_IRREGULAR.get(word, word), "VERB" if main else "AUX"))
                continue
            if closed == "ADP" and prev_tag == "VERB" and (i + 1 == len(toks) or toks[i + 1] in _CLOSED):
                out.append((word, "ADP"))  # particles of phrasal verbs stay ADP, as spaCy's UD tags
            else:
                out.append((word, closed))
            continue
        if word in _VERBS:
            # a bare lemma after a determiner/adjective is a noun ("a walk", "a quick jump")
            tag_ = "NOUN" if prev_tag in ("DET", "ADJ", "NUM") else "VERB"
            out.append((word, tag_))
            continue
        lemma = _strip_verb(word)
        if lemma is not None:
            if word.endswith("ing") and prev_tag in ("DET", "ADJ"):
                out.append((word, "NOUN"))
            elif word.endswith("s") and not word.endswith("ss") and prev_tag in ("DET", "ADJ", "NUM"):
                out.append((lemma, "NOUN"))
            else:
                out.append((lemma, "VERB"))
            continue
        if word.endswith("ly") and len(word) > 4:
            out.append((word, "ADV"))
            continue
        if word.endswith(("ful", "ous", "ive", "ish", "ic", "al", "less")) and len(word) > 5:
            out.append((word, "ADJ"))
            continue
        out.append((_singular(word), "NOUN"))
    return out


def tokens(text: str) -> str:
    """HumanML3D token string of a caption: ``lemma/TAG`` words joined by spaces."""
    return " ".join(f"{lemma}/{tag_}" for lemma, tag_ in tag(text))
