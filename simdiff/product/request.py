"""A checked generation request: what ``simdiff generate`` validates before loading any model.

Pure Python + numpy (no torch), so bad input fails in milliseconds with one line naming the value.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from simdiff.diffusion.config import MAX_SEED, SamplingConfig
from simdiff.errors import SimdiffError
from simdiff.inference.timeline import MAX_SEGMENT_FRAMES, Segment
from simdiff.motion.skeleton import FPS, MAX_FRAMES, MIN_GENERATE_FRAMES
from simdiff.sim.env import EARTH_GRAVITY, Environment

MAX_SAMPLES: int = 64
"""Most samples per run (each is sampled, written and rendered)."""
MAX_COMPARE: int = 8
"""Most environments in one ``--compare`` video."""
COMPARE_KEYS: tuple[str, ...] = ("gravity", "wind_x", "wind_y")
"""Environment components ``--compare`` can vary."""
FORMATS: tuple[str, ...] = ("npy", "bvh", "glb", "gif", "mp4")
"""Output kinds: ``npy`` = joints + features, ``bvh``, ``glb`` (glTF binary, skinned body), and the ``gif``/``mp4``
stick video."""
DEFAULT_FORMATS: tuple[str, ...] = ("npy", "bvh", "gif")
VIDEO_FORMATS: tuple[str, ...] = ("gif", "mp4")
MAX_PROMPT_CHARS: int = 500
"""Longest prompt in characters (after collapsing white space), for the CLI and the viewer alike."""


@dataclass(frozen=True)
class GenerationRequest:
    """Everything one ``simdiff generate`` run does, already validated.

    Attributes:
        text: the prompt (stripped, non-empty).
        frames: motion length in frames at 20 fps, 10..196.
        envs: the environments φ to generate under: one, or several for ``--compare``.
        compare: the φ component varied across ``envs`` (``gravity``, ``wind_x``, ``wind_y``) or None.
        seed: noise seed of sample 0; sample k uses ``seed + k`` (the same under every environment).
        num_samples: samples per environment.
        sampling: the sampling configuration (the model's ``sampling.json`` with the user's options over it).
        formats: output kinds, a subset of :data:`FORMATS`.
        force: environments outside the trained range were allowed.
        keyframes: (frames, 22, 3) joints to meet, NaN = free (:mod:`simdiff.inference.keyframes`), or None.
        keyframes_file: where they were read from.
        timeline: the segments of ``--timeline`` (:mod:`simdiff.inference.timeline`), or None; ``text`` is then
            their texts joined by ", then", ``frames`` their sum and ``envs`` Earth's (each segment has its own).
    """

    text: str
    frames: int = 120
    envs: tuple[Environment, ...] = (Environment(),)
    compare: str | None = None
    seed: int = 0
    num_samples: int = 1
    sampling: SamplingConfig = SamplingConfig()
    formats: tuple[str, ...] = DEFAULT_FORMATS
    force: bool = False
    keyframes: np.ndarray | None = field(default=None, compare=False, repr=False)
    keyframes_file: str | None = None
    timeline: tuple | None = None

    @property
    def seconds(self) -> float:
        """Motion length in seconds."""
        return self.frames / FPS

    @property
    def video_formats(self) -> tuple[str, ...]:
        """The requested video kinds (``gif``, ``mp4``), possibly none."""
        return tuple(f for f in self.formats if f in VIDEO_FORMATS)

    def with_envs(self, envs: tuple[Environment, ...]) -> GenerationRequest:
        """A copy with other environments (used when a backbone-only model ignores φ)."""
        return replace(self, envs=envs, compare=None)


def check_text(text: str) -> str:
    """The prompt with white space collapsed; blank or over :data:`MAX_PROMPT_CHARS` raises."""
    stripped = " ".join(str(text).split())
    if not stripped:
        raise SimdiffError("the text prompt is empty; describe the motion, e.g. \"a person jumps forward\"")
    if len(stripped) > MAX_PROMPT_CHARS:
        raise SimdiffError(f"the text prompt is {len(stripped)} characters long; the limit is {MAX_PROMPT_CHARS}")
    return stripped


def frames_from(length_s: float | None = None, default: int = 120) -> int:
    """Frames at 20 fps from ``--length SECONDS`` (``default`` frames when None).

    Raises:
        SimdiffError: non-finite, or outside 10..196 frames (0.5..9.8 s).
    """
    if length_s is None:
        return default
    if not math.isfinite(length_s):
        raise SimdiffError(f"--length must be a number of seconds, got {length_s}")
    n = int(round(length_s * FPS))
    if not MIN_GENERATE_FRAMES <= n <= MAX_FRAMES:
        raise SimdiffError(f"--length {length_s:g} s is {n} frames; it must be {MIN_GENERATE_FRAMES}..{MAX_FRAMES} "
                           f"frames ({MIN_GENERATE_FRAMES / FPS:g}..{MAX_FRAMES / FPS:g} s at {FPS} fps)")
    return n


def parse_compare(spec: str) -> tuple[str, tuple[float, ...]]:
    """``"gravity=-9.81,-3.7,-1.6"`` → ``("gravity", (-9.81, -3.7, -1.6))``; also ``wind_x=`` and ``wind_y=``.

    Raises:
        SimdiffError: unknown component, no ``=``, a value that is not a finite number, fewer than
            2 or more than :data:`MAX_COMPARE` values, or a repeated value.
    """
    usage = "expected gravity=G1,G2,... or wind_x=X1,X2,... or wind_y=Y1,Y2,..."
    key, sep, rest = str(spec).partition("=")
    key = key.strip().lower().replace("-", "_")
    if not sep or key not in COMPARE_KEYS:
        raise SimdiffError(f"bad --compare {spec!r}: {usage}")
    values = []
    for item in rest.split(","):
        try:
            value = float(item)
        except ValueError:
            raise SimdiffError(f"bad --compare {spec!r}: {item.strip()!r} is not a number") from None
        if not math.isfinite(value):
            raise SimdiffError(f"bad --compare {spec!r}: {item.strip()!r} is not a finite number")
        values.append(value)
    if not 2 <= len(values) <= MAX_COMPARE:
        raise SimdiffError(f"bad --compare {spec!r}: give 2..{MAX_COMPARE} values, got {len(values)}")
    if len(set(values)) != len(values):
        raise SimdiffError(f"bad --compare {spec!r}: a value is repeated")
    return key, tuple(values)


def parse_formats(spec: str | None) -> tuple[str, ...]:
    """``"npy,bvh,gif"`` → ``("npy", "bvh", "gif")`` (None: :data:`DEFAULT_FORMATS`).

    Raises:
        SimdiffError: an unknown kind, or nothing to write.
    """
    kinds = DEFAULT_FORMATS if spec is None else tuple(dict.fromkeys(k.strip().lower() for k in spec.split(",") if k.strip()))
    bad = [k for k in kinds if k not in FORMATS]
    if bad:
        raise SimdiffError(f"unknown --format {bad[0]!r}; choose from {', '.join(FORMATS)} (comma-separated)")
    if not kinds:
        raise SimdiffError("nothing to write: --format is empty")
    return kinds


def environments(gravity: float, wind: tuple[float, float], compare: tuple[str, tuple[float, ...]] | None,
                 force: bool = False) -> tuple[Environment, ...]:
    """The validated environment(s): φ from ``gravity``/``wind``, one per ``compare`` value if given.

    Raises:
        SimdiffError: gravity ≥ 0 or non-finite, or (without ``force``) outside the trained range
            (g ∈ [−20, −1] m/s², |w| ≤ 10 N); the message names the value.
    """
    base = Environment(check_finite("--gravity", gravity), check_finite("--wind X", wind[0]),
                       check_finite("--wind Y", wind[1]))
    if compare is None:
        envs: tuple[Environment, ...] = (base,)
    else:
        key, values = compare
        field = {"gravity": "gravity", "wind_x": "wind_x", "wind_y": "wind_y"}[key]
        envs = tuple(replace(base, **{field: v}) for v in values)
    for env in envs:
        env.validate(force=force)
    return envs


def check_finite(name: str, value: float, minimum: float | None = None) -> float:
    """``value`` as float if finite (and ≥ ``minimum``); else a one-line error naming ``name``."""
    value = float(value)
    if not math.isfinite(value):
        raise SimdiffError(f"{name} must be a finite number, got {value}")
    if minimum is not None and value < minimum:
        raise SimdiffError(f"{name} must be ≥ {minimum:g}, got {value:g}")
    return value


def build_request(text: str | None, *, gravity: float | None = None, wind: tuple[float, float] | None = None,
                  length_s: float | None = None, seed: int = 0, num_samples: int = 1,
                  sampling: SamplingConfig = SamplingConfig(), compare: str | None = None,
                  formats: str | None = None, force: bool = False,
                  keyframes: str | Path | None = None, timeline: str | Path | None = None) -> GenerationRequest:
    """Validate every user option and return the request (raises :class:`SimdiffError` on the first bad one).
    ``keyframes``: a (T, 22, 3) .npy file, NaN = free; the motion then has its T frames. ``timeline``: a JSON file
    of segments (``text`` is then None)."""
    if timeline is not None:
        return _timeline_request(text, timeline, gravity=gravity, wind=wind, length_s=length_s, seed=seed,
                                 num_samples=num_samples, sampling=sampling, compare=compare, formats=formats,
                                 force=force, keyframes=keyframes)
    if text is None:
        raise SimdiffError("give the TEXT prompt, or --timeline FILE.json")
    if not 0 <= seed <= MAX_SEED:
        raise SimdiffError(f"--seed must be in 0..{MAX_SEED}, got {seed}")
    if not 1 <= num_samples <= MAX_SAMPLES:
        raise SimdiffError(f"--num-samples must be 1..{MAX_SAMPLES}, got {num_samples}")
    spec = parse_compare(compare) if compare is not None else None
    keys = None
    if keyframes is not None:
        from simdiff.inference.keyframes import load_keyframes  # numpy only

        keys = load_keyframes(keyframes)
        if length_s is not None and frames_from(length_s) != keys.shape[0]:
            raise SimdiffError(f"--length {length_s:g} s is {frames_from(length_s)} frames but the keyframes in "
                               f"{keyframes} have {keys.shape[0]}; leave --length out")
    return GenerationRequest(
        text=check_text(text),
        frames=frames_from(length_s) if keys is None else int(keys.shape[0]),
        envs=environments(EARTH_GRAVITY if gravity is None else gravity, (0.0, 0.0) if wind is None else tuple(wind),
                          spec, force),
        compare=spec[0] if spec else None,
        seed=int(seed),
        num_samples=int(num_samples),
        sampling=sampling,
        formats=parse_formats(formats),
        force=bool(force),
        keyframes=keys,
        keyframes_file=None if keyframes is None else str(keyframes),
    )


def _timeline_request(text: str | None, timeline: str | Path, *, gravity: float | None, wind: tuple | None,
                      length_s: float | None, seed: int, num_samples: int, sampling: SamplingConfig,
                      compare: str | None, formats: str | None, force: bool,
                      keyframes: str | Path | None) -> GenerationRequest:
    """:func:`build_request` for ``--timeline``: the options a timeline's segments give are refused."""
    given = [flag for flag, value in (("TEXT", text), ("--gravity", gravity), ("--wind", wind),
                                       ("--length", length_s), ("--compare", compare), ("--keyframes", keyframes))
             if value is not None]
    if given:
        raise SimdiffError(f"--timeline gives each segment's text, length and environment; leave {given[0]} out")
    segments = read_timeline(timeline, force)
    request = build_request(segments[0].text, seed=seed, num_samples=num_samples, sampling=sampling,
                            formats=formats, force=force)
    joined = ", then ".join(s.text for s in segments)
    if len(joined) > MAX_PROMPT_CHARS:
        joined = joined[: MAX_PROMPT_CHARS - 1] + "…"
    return replace(request, text=joined, frames=sum(s.frames for s in segments), timeline=segments)


# Timelines (``generate --timeline``): checked here, sampled by :mod:`simdiff.inference.timeline`.

MAX_SEGMENTS: int = 100
"""Most segments in one timeline."""
KEYS: frozenset[str] = frozenset({"text", "seconds", "gravity", "wind"})


def read_timeline(path: str | Path, force: bool = False) -> tuple[Segment, ...]:
    """The checked segments of a timeline file; one line naming the file, the segment and the bad value otherwise.
    ``force`` widens the environment ranges as ``generate --force`` does."""
    path = Path(path)
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise SimdiffError(f"no timeline file {str(path)!r}") from None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise SimdiffError(f"{path}: not a JSON timeline ({exc})") from None
    return parse_timeline(data, str(path), force)


def parse_timeline(data: Any, name: str = "the timeline", force: bool = False) -> tuple[Segment, ...]:
    """:func:`read_timeline` for parsed JSON: a non-empty list of segment objects."""
    if not isinstance(data, list) or not data:
        raise SimdiffError(f"{name} must be a non-empty JSON list of segments "
                           '[{"text": ..., "seconds": ..., "gravity"?: ..., "wind"?: [x, y]}, ...]')
    if len(data) > MAX_SEGMENTS:
        raise SimdiffError(f"{name} has {len(data)} segments; the most is {MAX_SEGMENTS}")
    segments = []
    for i, seg in enumerate(data):
        where = f"{name}: segment {i}"
        if not isinstance(seg, dict):
            raise SimdiffError(f"{where} is {type(seg).__name__}, not an object with text and seconds")
        unknown = sorted(set(seg) - KEYS)
        if unknown:
            raise SimdiffError(f"{where} has an unknown key {unknown[0]!r}; use text, seconds, gravity, wind")
        for key in ("text", "seconds"):
            if key not in seg:
                raise SimdiffError(f"{where} has no {key!r}")
        if not isinstance(seg["text"], str):
            raise SimdiffError(f"{where}: text must be a string, got {seg['text']!r}")
        try:
            text = check_text(seg["text"])
            seconds = check_finite(f"{where}: seconds", _number(seg["seconds"], f"{where}: seconds"))
            gravity = check_finite(f"{where}: gravity", _number(seg.get("gravity", EARTH_GRAVITY), f"{where}: gravity"))
            wind = seg.get("wind", [0.0, 0.0])
            if not isinstance(wind, list) or len(wind) != 2:
                raise SimdiffError(f"{where}: wind must be [x, y] in newtons, got {wind!r}")
            wx, wy = (check_finite(f"{where}: wind", _number(w, f"{where}: wind")) for w in wind)
            env = Environment(gravity, wx, wy).validate(force)
        except SimdiffError as exc:
            message = str(exc)
            raise SimdiffError(message if message.startswith(where) else f"{where}: {message}") from None
        low = MIN_GENERATE_FRAMES if i == 0 else 1
        frames = round(seconds * FPS) if abs(seconds) <= MAX_FRAMES else -1
        if not low <= frames <= (MAX_FRAMES if i == 0 else MAX_SEGMENT_FRAMES):
            top = (MAX_FRAMES if i == 0 else MAX_SEGMENT_FRAMES) / FPS
            raise SimdiffError(f"{where}: seconds {seconds:g} is outside {low / FPS:g}..{top:g} (one segment is one "
                               "network window; split longer ones)")
        segments.append(Segment(text, frames, env))
    return tuple(segments)


def _number(value: Any, name: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise SimdiffError(f"{name} must be a number, got {value!r}")
    try:
        return float(value)
    except OverflowError:
        raise SimdiffError(f"{name} must be a finite number, got an integer of {len(str(value))} digits") from None
