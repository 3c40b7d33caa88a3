"""Readable captions from CMU's terse motion descriptions, a coarse motion type, and the KIT-ML sentences
that cover a window of a trial.

CMU describes a trial in a few words ("run/jog, veer left", "basketball - forward
dribble", "TooCoolWalk"). :func:`describe` turns that into a few varied HumanML3D-style
sentences ("a person jogs forward and veers to the left."), deterministically for a given
seed. Phrases are matched against a hand-written table first, then simple rules
(``<style> walk``, a leading verb, a turn angle); anything else becomes "performs <phrase>".
"""

from __future__ import annotations

import hashlib
import random
import re

from simdiff.data.corpus.cmu_sources import Trial
from simdiff.data.corpus.pos import tokens as pos_tokens
from simdiff.data.corpus.windows import Window
from simdiff.motion.skeleton import FPS

SUBJECTS: tuple[str, ...] = ("a person", "someone", "a person", "the person", "a human")
"""Sentence subjects; "a person" is weighted double, as in HumanML3D."""

# Each phrase maps to alternative verb phrases, third person singular present.
_TABLE: dict[str, tuple[str, ...]] = {
    "walk": ("walks forward", "walks straight ahead", "takes a walk forward"),
    "walk forward": ("walks forward", "walks straight ahead"),
    "walk straight": ("walks in a straight line", "walks straight forward"),
    "forward": ("walks forward", "moves forward"),
    "small forward": ("takes small steps forward", "shuffles forward with short steps"),
    "backward": ("walks backward", "steps backwards"),
    "sideways": ("walks sideways", "side-steps"),
    "normal walk": ("walks normally", "walks at a normal pace"),
    "slow walk": ("walks slowly", "walks forward at a slow pace"),
    "brisk walk": ("walks briskly", "walks quickly forward"),
    "quick walk": ("walks quickly", "walks forward at a fast pace"),
    "walk on uneven terrain": ("walks carefully over uneven ground", "walks across uneven terrain"),
    "walk to run": ("walks and then breaks into a run", "starts walking and speeds up into a run"),
    "walk8": ("walks in a figure eight", "walks along a figure-eight path"),
    "walk figure8": ("walks in a figure eight", "walks along a figure-eight path"),
    "walk digital8": ("walks a squared-off figure eight", "walks along a figure-eight path with sharp corners"),
    "digital8": ("walks a squared-off figure eight", "walks along a figure-eight path with sharp corners"),
    "mummy walk": ("walks stiffly like a mummy with arms held out", "walks like a mummy"),
    "mummy8": ("walks like a mummy in a figure eight", "walks stiffly in a figure eight with arms out"),
    "mummy digital8": ("walks like a mummy along a squared-off figure eight",),
    "exaggerated stride": ("walks with exaggerated strides", "takes long exaggerated steps"),
    "march": ("marches forward", "marches with high knees"),
    "limp": ("limps forward", "walks with a limp"),
    "hurt leg walk": ("walks with a hurt leg", "limps on an injured leg"),
    "drag bad leg walk": ("walks dragging a bad leg", "drags an injured leg while walking"),
    "hurt stomach walk": ("walks hunched over, holding a sore stomach", "walks as if the stomach hurts"),
    "achey walk": ("walks stiffly as if aching", "walks with an achy body"),
    "careful walk looking around": ("walks carefully while looking around", "walks cautiously, looking around"),
    "traffic walk": ("walks and looks both ways as if crossing traffic", "walks and stops as if in traffic"),
    "too cool walk": ("walks with a very cool swagger", "struts along with a cool attitude"),
    "cool walk": ("walks with a cool swagger", "struts forward casually"),
    "ghetto walk": ("walks with a swagger", "walks with a loose, swaying swagger"),
    "macho walk": ("walks in a macho way", "walks with a proud, macho swagger"),
    "lavish walk": ("walks in a grand, lavish way", "walks with flamboyant steps"),
    "sexy walk": ("walks with swaying hips", "walks in a seductive way"),
    "shy walk": ("walks shyly", "walks timidly with the head down"),
    "sad walk": ("walks sadly", "walks slowly with a sad posture"),
    "depressed walk": ("walks in a depressed way", "walks slowly with slumped shoulders"),
    "scared walk": ("walks fearfully", "walks in a scared way"),
    "clumsy walk": ("walks clumsily", "walks in a clumsy, stumbling way"),
    "run": ("runs forward", "runs"),
    "run/jog": ("jogs forward", "runs at a jog"),
    "jog": ("jogs", "jogs in place"),
    "run right": ("runs toward the right", "runs and curves to the right"),
    "run turn left": ("runs and turns left", "runs forward and makes a left turn"),
    "run turn right": ("runs and turns right", "runs forward and makes a right turn"),
    "run stop run": ("runs, stops and runs again", "runs, comes to a stop, then runs on"),
    "run to quick stop": ("runs and comes to a quick stop", "runs then stops suddenly"),
    "run jump stop run": ("runs, jumps, stops and runs again",),
    "run jump over": ("runs and jumps over an obstacle", "runs forward and leaps over something"),
    "run duck underneath": ("runs and ducks under an obstacle", "runs and crouches to pass under something"),
    "run dive over roll run": ("runs, dives over an obstacle, rolls and keeps running",),
    "sudden stop": ("stops suddenly", "comes to an abrupt stop"),
    "stop": ("stops", "comes to a stop"),
    "veer left": ("veers to the left", "drifts to the left"),
    "veer right": ("veers to the right", "drifts to the right"),
    "turn": ("turns", "turns around"),
    "turn around": ("turns around", "turns back the other way"),
    "turn step": ("does a turning step", "steps and turns"),
    "sideways steps": ("steps sideways", "takes a few steps to the side"),
    "90-degree left turn": ("turns 90 degrees to the left", "makes a sharp left turn"),
    "90-degree right turn": ("turns 90 degrees to the right", "makes a sharp right turn"),
    "90-degree left turns": ("makes 90-degree turns to the left", "turns sharply left"),
    "90-degree right turns": ("makes 90-degree turns to the right", "turns sharply right"),
    "jump": ("jumps", "jumps up"),
    "high jump": ("jumps high", "does a high jump"),
    "forward jump": ("jumps forward", "leaps forward with both feet"),
    "forward jumps": ("jumps forward several times", "hops forward with both feet"),
    "jump forward": ("jumps forward", "leaps forward with both feet"),
    "jump small forward": ("does a small jump forward", "hops forward a short distance"),
    "jump up and down": ("jumps up and down", "jumps in place"),
    "jump down": ("jumps down", "jumps down from something"),
    "jump turn": ("jumps and turns in the air", "does a turning jump"),
    "small jump turn": ("does a small turning jump", "hops and turns"),
    "further jump turn": ("does a long turning jump", "jumps far and turns in the air"),
    "jump twist": ("jumps and twists in the air", "does a twisting jump"),
    "jump kick": ("jumps and kicks", "does a jumping kick"),
    "jump and spin kick": ("jumps and does a spinning kick", "does a jumping spin kick"),
    "hop on one foot": ("hops on one foot", "hops on one leg"),
    "leap": ("leaps", "takes a big leap"),
    "jumping jacks": ("does jumping jacks", "performs jumping jacks"),
    "side twists": ("twists the torso from side to side", "does side twists"),
    "squats": ("does squats", "squats down and stands up"),
    "stretches": ("stretches", "does some stretches"),
    "reach up": ("reaches up", "reaches both arms up"),
    "bend over": ("bends over", "bends forward at the waist"),
    "balance": ("balances", "keeps balance"),
    "balance on one leg": ("balances on one leg", "stands on one leg"),
    "outstretched arms": ("holds the arms outstretched", "stretches the arms out"),
    "cartwheel": ("does a cartwheel", "performs a cartwheel"),
    "cartwheels": ("does cartwheels", "performs a series of cartwheels"),
    "stretch and cartwheel": ("stretches and then does a cartwheel",),
    "crouch and flip backward on hands": ("crouches and flips backward onto the hands", "does a back handspring"),
    "hand stand kicks": ("does a handstand and kicks the legs", "kicks up into handstands"),
    "kick flip": ("does a kick flip", "kicks and flips over"),
    "kick flip stumble": ("tries a kick flip and stumbles", "does a kick flip and stumbles on landing"),
    "helicopter": ("spins the legs around like a helicopter", "does a breakdance helicopter move"),
    "fall on face": ("falls forward onto the face", "falls flat on the face"),
    "bannana peel slip": ("slips as if on a banana peel", "slips and falls backwards"),
    "get up from ground": ("gets up from the ground", "stands up from the floor"),
    "get up face down": ("gets up from lying face down", "pushes up from the floor and stands"),
    "get up laying on side": ("gets up from lying on the side", "stands up from lying on the floor"),
    "motor cycle pose": ("poses as if riding a motorcycle", "mimes riding a motorcycle"),
    "punch/strike": ("punches and strikes", "throws punches"),
    "swordplay": ("fights with a sword", "swings a sword"),
    "wash self": ("washes the body", "mimes washing", "scrubs the body as if in a shower"),
    "scoop up": ("scoops something up", "picks something up"),
    "rise": ("rises", "stands back up"),
    "lift arm": ("lifts an arm", "raises one arm"),
    "climb": ("climbs", "climbs up"),
    "sit": ("sits down", "takes a seat"),
    "dangle": ("dangles", "hangs down"),
    "dangle legs": ("dangles the legs", "lets the legs dangle"),
    "rock back": ("rocks back", "leans back"),
    "lower self to ground": ("lowers down to the ground", "climbs down to the ground"),
    "legs push off against": ("pushes off with the legs",),
    "grip bar": ("grips a bar", "holds on to a bar"),
    "swing body": ("swings the body", "swings back and forth"),
    "kick ball": ("kicks a ball", "kicks a soccer ball"),
    "dribble": ("dribbles a basketball", "bounces a basketball"),
    "forward dribble": ("dribbles a basketball while moving forward", "moves forward dribbling a ball"),
    "backward dribble": ("dribbles a basketball while moving backward", "moves backwards dribbling a ball"),
    "sideways dribble": ("dribbles a basketball while moving sideways", "side-steps while dribbling a ball"),
    "crossover dribble": ("does a crossover dribble", "switches the ball from hand to hand"),
    "dribble through legs": ("dribbles the ball through the legs",),
    "low": ("stays low", "crouches low"),
    "fast free style dribble": ("dribbles fast in free style", "dribbles a ball quickly"),
    "shoot": ("shoots the ball", "takes a shot"),
    "whirl": ("whirls around", "spins around"),
    "lambada dance": ("dances the lambada", "does a lambada dance"),
    "lindy hop2": ("dances the lindy hop", "does a lindy hop dance"),
    "lindy hop": ("dances the lindy hop", "does a lindy hop dance"),
    "pirouette": ("does a pirouette", "spins on one foot"),
    "pirouettes": ("does pirouettes", "spins on one foot several times"),
    "shifted-axis pirouette": ("does an off-axis pirouette", "spins on one foot leaning off axis"),
    "expressive arms": ("moves the arms expressively", "makes expressive arm movements"),
    "arms held high": ("holds the arms high", "raises both arms high"),
    "sideways arabesque": ("does a sideways arabesque", "extends a leg out to the side"),
    "side arabesque": ("does a side arabesque", "extends a leg out to the side"),
    "attitude/arabesque": ("holds an arabesque", "extends one leg behind in an arabesque"),
    "folding arms": ("folds the arms", "brings the arms in"),
    "bending back": ("bends backward", "arches the back"),
    "quasi-cou-de-pied": ("lifts a foot to the ankle", "raises one foot to the other ankle"),
    "raised leg above hip-height": ("raises a leg above hip height", "lifts one leg high"),
    "jete": ("does a ballet leap", "leaps from one foot to the other"),
    "small jetes": ("does small ballet leaps", "does small leaps from foot to foot"),
    "jete en tourant": ("does a turning leap", "leaps and turns in the air"),
    "grand jete en tourant": ("does a big turning leap", "does a large leap with a turn"),
    "cartwheel-like start": ("starts with a cartwheel-like move",),
    "rond de jambe in the air": ("circles a raised leg in the air", "draws circles with one leg in the air"),
    "glissade devant": ("glides forward", "does a gliding step forward"),
    "glissade derriere": ("glides backward", "does a gliding step backward"),
    "pointe tendue a terre": ("points a foot on the floor", "extends a pointed foot along the floor"),
    "upper body rotation": ("rotates the upper body", "twists the torso"),
    "retire derriere": ("draws a foot up behind the knee", "lifts a foot to the back of the knee"),
    "coupe dessous": ("does a quick cutting step", "shifts weight with a cutting step"),
    "fold in from side arabesque": ("folds in from a side arabesque", "brings a raised side leg in"),
    "curl inwards": ("curls inward", "curls the body in"),
    "lean forward": ("leans forward", "bends the body forward"),
    "bring back leg forward": ("brings the back leg forward", "swings the rear leg forward"),
    "arching arms": ("arches the arms", "moves the arms in an arc"),
    "folded in": ("holds a folded-in pose", "curls up"),
    "head lowered": ("lowers the head", "keeps the head down"),
    "leg bent": ("bends a leg", "keeps one leg bent"),
    "lean back on bent leg": ("leans back on a bent leg", "leans back and bends a knee"),
    "bend elbow by ear": ("bends an elbow by the ear", "raises a bent arm next to the head"),
    "dance": ("dances", "dances around"),
}

_CONTEXT: dict[str, str] = {
    "dance": "dance",
    "static dance pose": "dance",
    "basketball": "basketball",
    "soccer": "soccer",
    "playground": "playground",
    "navigate": "",
}

_STYLE_ADVERBS: dict[str, str] = {
    "slow": "slowly", "quick": "quickly", "fast": "quickly", "careful": "carefully",
    "clumsy": "clumsily", "sad": "sadly", "happy": "happily", "shy": "shyly",
    "proud": "proudly", "angry": "angrily", "tired": "tiredly", "casual": "casually",
}

_VERB3: dict[str, str] = {
    "walk": "walks", "run": "runs", "jog": "jogs", "jump": "jumps", "hop": "hops",
    "turn": "turns", "step": "steps", "kick": "kicks", "punch": "punches", "sit": "sits",
    "stand": "stands", "crawl": "crawls", "roll": "rolls", "climb": "climbs", "fall": "falls",
    "spin": "spins", "stretch": "stretches", "bend": "bends", "lean": "leans", "reach": "reaches",
    "wave": "waves", "throw": "throws", "catch": "catches", "dance": "dances", "skip": "skips",
    "squat": "squats", "kneel": "kneels", "lift": "lifts", "swing": "swings", "push": "pushes",
    "pull": "pulls", "carry": "carries", "get": "gets", "march": "marches", "stop": "stops",
    "look": "looks", "leap": "leaps", "balance": "balances", "twist": "twists", "crouch": "crouches",
    "lie": "lies", "go": "goes", "do": "does", "duck": "ducks", "dive": "dives", "sweep": "sweeps",
    "mop": "mops", "box": "boxes", "drink": "drinks", "eat": "eats", "pick": "picks",
    "shake": "shakes", "clap": "claps", "salute": "salutes", "bow": "bows", "stumble": "stumbles",
    "slip": "slips", "swim": "swims", "sneak": "sneaks", "tiptoe": "tiptoes", "wash": "washes",
}

MOTION_TYPES: tuple[str, ...] = (
    "dance", "acrobatics", "sports", "exercise", "ground", "climb", "jump", "run", "walk", "other",
)
"""Coarse motion categories, checked in this order (first match wins)."""

_TYPE_WORDS: dict[str, tuple[str, ...]] = {
    "dance": ("dance", "pirouette", "arabesque", "jete", "lambada", "lindy", "whirl", "glissade", "ballet"),
    "acrobatics": ("cartwheel", "flip", "handstand", "hand stand", "helicopter", "dive", "roll", "backflip"),
    "sports": ("basketball", "dribble", "soccer", "kick", "punch", "strike", "sword", "shoot", "box"),
    "exercise": ("jumping jacks", "squat", "stretch", "side twist", "balance", "exercise"),
    "ground": ("get up", "fall", "slip", "crawl", "lying", "laying", "lie down"),
    "climb": ("climb", "grip bar", "swing body", "hang"),
    "jump": ("jump", "hop", "leap"),
    "run": ("run", "jog", "sprint"),
    "walk": ("walk", "march", "limp", "stride", "step", "forward", "backward", "sideways",
             "navigate", "mummy", "digital8", "180", "270", "360", "90", "stop"),
}


def split_camel(text: str) -> str:
    """'TooCoolWalk' -> 'too cool walk', 'walkFigure8' -> 'walk figure8' (lower-cased)."""
    spaced = re.sub(r"(?<=[a-z])(?=[A-Z])", " ", text)
    return re.sub(r"\s+", " ", spaced).strip().lower()


def motion_type(description: str) -> str:
    """Coarse category of a CMU description (one of :data:`MOTION_TYPES`)."""
    text = split_camel(description)
    for kind in MOTION_TYPES[:-1]:
        if any(word in text for word in _TYPE_WORDS[kind]):
            return kind
    return "other"


def _parse(description: str) -> tuple[str, list[str]]:
    """(context, action phrases) of a CMU description."""
    text = split_camel(description)
    context = ""
    if " - " in text:
        head, text = text.split(" - ", 1)
        context = _CONTEXT.get(head.strip(), head.strip())
    phrases = [p.strip(" .;") for p in re.split(r"[,;]", text) if p.strip(" .;")]
    return context, phrases


def _phrase_options(phrase: str, context: str) -> tuple[str, ...]:
    """Alternative verb phrases for one action phrase."""
    if phrase in _TABLE:
        return _TABLE[phrase]
    if phrase.endswith("s") and phrase[:-1] in _TABLE:
        return _TABLE[phrase[:-1]]
    if re.fullmatch(r"\d{2,3}", phrase):
        return (f"walks and turns {phrase} degrees", f"turns {phrase} degrees while walking")
    words = phrase.split()
    if len(words) >= 2 and words[-1] in ("walk", "run", "jog") and words[0] not in _VERB3:
        verb = _VERB3[words[-1]]
        style = " ".join(words[:-1])
        adverb = _STYLE_ADVERBS.get(style)
        if adverb:
            return (f"{verb} {adverb}", f"{verb} in a {style} way")
        return (f"{verb} in a {style} way", f"does a {style} {words[-1]}")
    if words and words[0] in _VERB3:
        rest = " ".join(words[1:])
        return ((f"{_VERB3[words[0]]} {rest}").strip(),)
    if context == "dance":
        return (f"dances a {phrase}", f"performs a {phrase} dance move")
    return (f"performs a {phrase} motion", f"does a {phrase}")


def _seeded(key: str, seed: int) -> random.Random:
    digest = hashlib.sha256(f"{seed}:{key}".encode()).digest()
    return random.Random(int.from_bytes(digest[:8], "little"))


def _join(parts: list[str], style: int) -> str:
    """Join verb phrases: style 0 "a, b and c", 1 "a, then b", 2 "a, then b and finally c"."""
    if len(parts) == 1:
        return parts[0]
    if style == 1 and len(parts) == 2:
        return f"{parts[0]}, then {parts[1]}"
    if style == 2:
        if len(parts) == 2:
            return f"{parts[0]} and then {parts[1]}"
        return ", then ".join(parts[:-1]) + f" and finally {parts[-1]}"
    return ", ".join(parts[:-1]) + f" and {parts[-1]}"


def _contextualise(parts: list[str], context: str, variant: int) -> list[str]:
    """Add the activity ("dance", "playground") to the verb phrases where it reads well."""
    if context == "dance":
        if not any("danc" in p for p in parts):
            return parts + ["dances"] if variant % 2 else [f"dances and {parts[0]}"] + parts[1:]
        return parts
    if context == "playground" and parts:
        return parts[:-1] + [f"{parts[-1]} on a playground"] if variant % 2 == 0 else parts
    if context == "soccer":
        return [p.replace("a ball", "a soccer ball") for p in parts]
    return parts


def _forwardise(parts: list[str]) -> list[str]:
    """'runs' -> 'runs forward' when a turn, veer or stop follows (reads like HumanML3D)."""
    turns = ("veer", "turn", "drift", "stop")
    if len(parts) >= 2 and parts[0] in ("runs", "jogs") and any(w in parts[1] for w in turns):
        return [f"{parts[0]} forward"] + parts[1:]
    return parts


def describe(description: str, *, n: int = 3, seed: int = 0, key: str = "") -> list[str]:
    """Up to ``n`` distinct sentences for a CMU description (deterministic in seed and key).

    Args:
        description: CMU text, e.g. "run/jog, veer left" or "basketball - forward dribble".
        n: number of captions wanted.
        seed: corpus seed.
        key: extra key (e.g. the clip id) so different clips get different variants.
    Returns:
        Lower-case sentences ending in a full stop; the first is the plain reading ("a person
        jogs forward and veers to the left."), the others vary verbs, subject and joining.
    """
    context, phrases = _parse(description)
    if not phrases:
        phrases = ["move"]
        context = ""
    options = [_phrase_options(p, context) for p in phrases]
    rng = _seeded(f"{key}|{description}", seed)
    out: list[str] = []
    for attempt in range(4 * n):
        variant = attempt % 3
        if attempt == 0:  # the plain reading first: "a person jogs forward and veers to the left."
            parts, subject = [opts[0] for opts in options], SUBJECTS[0]
        else:
            parts = [opts[(attempt + rng.randrange(len(opts))) % len(opts)] for opts in options]
            subject = SUBJECTS[rng.randrange(len(SUBJECTS))]
        parts = _forwardise(_contextualise(parts, context, attempt))
        sentence = f"{subject} {_join(parts, variant)}."
        if sentence not in out:
            out.append(sentence)
        if len(out) == n:
            break
    return out


def caption_line(text: str, start: float = 0.0, end: float = 0.0) -> str:
    """One HumanML3D text-file line: ``caption#tokens#start#end`` (seconds; 0 0 = whole clip)."""
    clean = " ".join(text.replace("#", " ").split())
    return f"{clean}#{pos_tokens(clean)}#{start:.1f}#{end:.1f}"


def kit_for_window(trial: Trial, window: Window) -> list[str]:
    """KIT-ML sentences whose time span covers at least half of the window."""
    start, stop = window.start / FPS, window.stop / FPS
    out: list[str] = []
    for entry in trial.kitml:
        a, b = float(entry["start"]), float(entry["end"])  # type: ignore[arg-type]
        if b <= a:  # no span given: the whole trial
            a, b = 0.0, float("inf")
        overlap = max(0.0, min(b, stop) - max(a, start))
        text = " ".join(str(entry["text"]).split())
        if overlap >= 0.5 * (stop - start) and text and text not in out:
            out.append(text)
    return out
