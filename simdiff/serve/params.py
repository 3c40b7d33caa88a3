"""Validated parameters of the viewer's requests: a generation (prompt box, sliders, pinned poses), a re-play of
a motion on screen under φ, a timeline of prompts.

Ranges match the ``simdiff generate`` CLI: gravity g_z ∈ [−20, −1] m/s², |wind| ≤ 10 N,
adapter strength α ∈ [0, 2], length 0.5 .. 9.8 s at 20 fps; a timeline's segments are checked by
:func:`simdiff.product.request.parse_timeline`, as ``generate --timeline``'s.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import asdict, dataclass, field
from typing import Any

from simdiff.diffusion.config import MAX_FLIGHT_PASSES
from simdiff.errors import SimdiffError
from simdiff.inference.timeline import Segment
from simdiff.motion.skeleton import FPS, MAX_FRAMES, MIN_GENERATE_FRAMES
from simdiff.product.request import MAX_PROMPT_CHARS, check_text, parse_timeline
from simdiff.sim.env import EARTH_GRAVITY, GRAVITY_RANGE, MAX_WIND

ALPHA_RANGE: tuple[float, float] = (0.0, 2.0)
"""Adapter strength α bounds (0 = backbone only, 1 = trained strength)."""
MAX_SECONDS: float = MAX_FRAMES / FPS
"""Longest motion in seconds (9.8 s)."""
MIN_SECONDS: float = MIN_GENERATE_FRAMES / FPS
"""Shortest motion in seconds (10 frames at 20 fps)."""
MAX_STEPS: int = 200
"""Most DDIM steps a request from the page may ask for (the default is 50): one request holds the
model for at most about 4× a default generation, so a queue of them drains in bounded time."""
GUIDANCE_RANGE: tuple[float, float] = (0.0, 20.0)
"""Classifier-free guidance scale bounds."""
ENV_GUIDANCE_RANGE: tuple[float, float] = (0.0, 10.0)
"""Environment guidance s_e bounds (1 = off)."""
MAX_TEXT: int = MAX_PROMPT_CHARS
"""Longest prompt in characters (the same limit as ``simdiff generate``)."""
MAX_REPLAY_FRAMES: int = 60 * FPS
"""Longest motion ``POST /api/edit`` re-plays (60 s: 8 network windows, about 8 default generations);
``simdiff edit`` takes longer ones."""
MAX_TIMELINE_SEGMENTS: int = 8
"""Most segments of one ``POST /api/timeline`` (one sample each); ``generate --timeline`` takes more."""


SAMPLING_FIELDS: tuple[str, ...] = ("steps", "eta", "guidance", "guidance_min_t", "alpha", "env_guidance",
                                    "edit_t", "foot_lock", "flight_passes")
"""The :class:`~simdiff.diffusion.config.SamplingConfig` fields a request may set (None: the model's value)."""


@dataclass(frozen=True)
class GenerateParams:
    """One generation: prompt, environment φ, length, seed and the sampling settings the request overrides.

    Attributes:
        text: the prompt (stripped, non-empty).
        gravity: g_z in m/s² (Earth −9.81).
        wind_x, wind_y: horizontal wind force in newtons (HumanML3D +X, +Z).
        seconds: motion length in seconds (20 fps).
        seed: noise seed (≥ 0).
        simulate: simulated finish: re-track the motion in the simulator under φ; the answer shows the
            simulated motion and carries the generated one and the tracking result in ``meta``.
        steps, eta, guidance, guidance_min_t, alpha, env_guidance, edit_t, foot_lock, flight_passes: the
            :class:`~simdiff.diffusion.config.SamplingConfig` fields, or None for the model's ``sampling.json``
            value, as ``simdiff generate``.
        pin_start, pin_end: None, or the number of a motion shown (an answer's ``motion``) whose first (last)
            pose the motion must start (end) in: keyframes of the motion's length, NaN but for that frame.
    """

    text: str
    gravity: float = EARTH_GRAVITY
    wind_x: float = 0.0
    wind_y: float = 0.0
    seconds: float = 6.0
    seed: int = 0
    simulate: bool = False
    steps: int | None = None
    eta: float | None = None
    guidance: float | None = None
    alpha: float | None = None
    env_guidance: float | None = None
    edit_t: int | None = None
    guidance_min_t: int | None = None
    foot_lock: float | None = None
    flight_passes: int | None = None
    pin_start: int | None = None
    pin_end: int | None = None

    def sampling(self) -> dict[str, Any]:
        """The sampling fields this request sets (the others are the model's)."""
        return {k: getattr(self, k) for k in SAMPLING_FIELDS if getattr(self, k) is not None}

    @property
    def frames(self) -> int:
        """Motion length in frames at 20 fps (10..196)."""
        return max(round(MIN_SECONDS * FPS), min(MAX_FRAMES, round(self.seconds * FPS)))

    def as_dict(self) -> dict[str, Any]:
        """Plain JSON-able values."""
        return asdict(self)


def limits() -> dict[str, Any]:
    """The accepted ranges, for the page's sliders (units: m/s², N, s)."""
    return {
        "gravity": list(GRAVITY_RANGE), "wind": MAX_WIND, "alpha": list(ALPHA_RANGE), "seconds": MAX_SECONDS,
        "min_seconds": MIN_SECONDS, "fps": FPS, "steps": MAX_STEPS, "guidance": list(GUIDANCE_RANGE), "text": MAX_TEXT,
        "env_guidance": list(ENV_GUIDANCE_RANGE), "edit_t": [0, 999], "guidance_min_t": [0, 999], "replay_seconds": MAX_REPLAY_FRAMES / FPS,
        "timeline_segments": MAX_TIMELINE_SEGMENTS,
    }


def _show(value: Any, limit: int = 40) -> str:
    """``repr(value)`` cut to ``limit`` characters (messages stay one short line)."""
    text = repr(value) if not isinstance(value, int) or abs(value) < 10**30 else f"a {len(str(abs(value)))}-digit integer"
    return text if len(text) <= limit else text[:limit - 3] + "..."


def _number(body: Mapping[str, Any], key: str, default: float) -> float:
    value = body.get(key, default)
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise SimdiffError(f"{key} must be a finite number, got {_show(value)}")
    try:
        number = float(value)
    except OverflowError:
        number = math.inf
    if not math.isfinite(number):
        raise SimdiffError(f"{key} must be a finite number, got {_show(value)}")
    return number


def _integer(body: Mapping[str, Any], key: str, default: int | None) -> int | None:
    value = body.get(key, default)
    if value is None:
        return None
    if isinstance(value, float) and value.is_integer():
        value = int(value)
    if isinstance(value, bool) or not isinstance(value, int):
        raise SimdiffError(f"{key} must be an integer, got {_show(value)}")
    return value


def _check_range(key: str, value: float, low: float, high: float, unit: str = "") -> None:
    if not low <= value <= high:
        shown = f"{value:g}" if isinstance(value, float) or abs(value) < 10**30 else _show(value)
        raise SimdiffError(f"{key} must be in [{low:g}, {high:g}]{unit}, got {shown}")


def check_fields(body: Any, known: set[str]) -> dict[str, Any]:
    """``body`` if it is a JSON object with no field outside ``known``; else a one-line error."""
    if not isinstance(body, dict):
        raise SimdiffError(f"request body must be a JSON object, got {type(body).__name__}")
    unknown = sorted(set(body) - known)
    if unknown:
        raise SimdiffError(f"unknown field {_show(unknown[0])} (known: {', '.join(sorted(known))})")
    return body


def parse_text(value: Any, key: str = "text") -> str:
    """A prompt: a non-empty string of valid Unicode, white space collapsed (:func:`check_text`)."""
    if not isinstance(value, str) or not value.strip():
        raise SimdiffError(f"{key} must be a non-empty prompt, got {_show(value)}")
    _check_unicode(value, key)
    return check_text(value)


def _check_unicode(value: str, key: str) -> None:
    """JSON's ``\\ud800`` decodes to a lone surrogate, which no encoder takes: refuse it here."""
    if not value.isascii():
        try:
            value.encode("utf-8")
        except UnicodeEncodeError:
            raise SimdiffError(f"{key} must be valid Unicode (it holds a lone surrogate escape)") from None


def parse_env(body: Mapping[str, Any]) -> dict[str, float]:
    """``{gravity, wind_x, wind_y}`` (m/s², N, N; default Earth without wind) within the sliders' ranges."""
    env = {"gravity": _number(body, "gravity", EARTH_GRAVITY)}
    _check_range("gravity", env["gravity"], *GRAVITY_RANGE, " m/s²")
    for key in ("wind_x", "wind_y"):
        env[key] = _number(body, key, 0.0)
        _check_range(key, env[key], -MAX_WIND, MAX_WIND, " N")
    return env


def parse_seed(body: Mapping[str, Any]) -> int:
    """The noise seed, 0 ≤ seed < 2**63 (default 0)."""
    seed = _integer(body, "seed", 0)
    if seed is None or not 0 <= seed < 2**63:
        raise SimdiffError(f"seed must be a non-negative integer below 2**63, got {_show(seed)}")
    return seed


def parse_sampling(body: Mapping[str, Any]) -> dict[str, Any]:
    """The :data:`SAMPLING_FIELDS` a request gives (None: the model's), each within its range."""
    sampling: dict[str, Any] = {}
    for key, (low, high) in {"steps": (1, MAX_STEPS), "edit_t": (0, 999), "guidance_min_t": (0, 999),
                               "flight_passes": (0, MAX_FLIGHT_PASSES)}.items():
        value = _integer(body, key, None)
        if value is not None:
            _check_range(key, value, low, high)
        sampling[key] = value
    for key, (low, high) in {"eta": (0.0, 1.0), "guidance": GUIDANCE_RANGE, "alpha": ALPHA_RANGE,
                             "env_guidance": ENV_GUIDANCE_RANGE, "foot_lock": (0.0, 1.0)}.items():
        if body.get(key) is not None:
            sampling[key] = _number(body, key, 0.0)
            _check_range(key, sampling[key], low, high)
    return sampling


def parse_motion(body: Mapping[str, Any], key: str) -> int | None:
    """A reference to a motion shown: the whole number ``motion`` of an earlier answer (None when not given)."""
    value = body.get(key)
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, int) or not 1 <= value < 2**31:
        raise SimdiffError(f"{key} must be the number of a motion shown (an answer's \"motion\"), got {_show(value)}")
    return value


def parse_generate(body: Any) -> GenerateParams:
    """Validate a ``POST /api/generate`` JSON body.

    Args:
        body: the decoded JSON object ``{text, gravity, wind_x, wind_y, seconds, seed, simulate, steps, eta,
            guidance, guidance_min_t, alpha, env_guidance, edit_t, foot_lock, flight_passes, pin_start, pin_end}``; everything but ``text`` is
            optional.
    Raises:
        SimdiffError: one line naming the bad field and value.
    """
    check_fields(body, set(GenerateParams.__dataclass_fields__))
    text = parse_text(body.get("text"))
    env = parse_env(body)
    seconds = _number(body, "seconds", GenerateParams.seconds)
    _check_range("seconds", seconds, MIN_SECONDS, MAX_SECONDS)
    simulate = body.get("simulate", False)
    if not isinstance(simulate, bool):
        raise SimdiffError(f"simulate must be true or false, got {_show(simulate)}")
    return GenerateParams(text=text, seconds=seconds, seed=parse_seed(body), simulate=simulate, **env,
                          **parse_sampling(body), pin_start=parse_motion(body, "pin_start"),
                          pin_end=parse_motion(body, "pin_end"))


@dataclass(frozen=True)
class ReplayParams:
    """One ``POST /api/edit``: the motion ``source`` (an answer's ``motion`` number) re-played under φ.

    Attributes:
        source: the motion's number.
        gravity, wind_x, wind_y: φ in m/s², N, N.
        seed: noise seed (window k of a long motion uses seed + k).
        text: what the motion shows (optional; empty: no text guidance), as ``simdiff edit --text``.
        settings: the sampling fields the request gives (:func:`parse_sampling`).
    """

    source: int
    gravity: float = EARTH_GRAVITY
    wind_x: float = 0.0
    wind_y: float = 0.0
    seed: int = 0
    text: str = ""
    settings: dict[str, Any] = field(default_factory=dict)

    def sampling(self) -> dict[str, Any]:
        """The sampling fields this request sets (the others are the model's)."""
        return {k: v for k, v in self.settings.items() if v is not None}

    def as_dict(self) -> dict[str, Any]:
        """Plain JSON-able values (the sampling fields given at the top level)."""
        return {"source": self.source, "gravity": self.gravity, "wind_x": self.wind_x, "wind_y": self.wind_y,
                "seed": self.seed, "text": self.text, **self.sampling()}


def parse_replay(body: Any) -> ReplayParams:
    """Validate a ``POST /api/edit`` body ``{source, gravity, wind_x, wind_y, seed, text, steps, eta, guidance,
    guidance_min_t, alpha, env_guidance, edit_t, foot_lock, flight_passes}`` (all but ``source`` optional); one line naming the bad value."""
    check_fields(body, {"source", "gravity", "wind_x", "wind_y", "seed", "text", *SAMPLING_FIELDS})
    source = parse_motion(body, "source")
    if source is None:
        raise SimdiffError("source must be the number of a motion shown (an answer's \"motion\"), got nothing")
    text = "" if body.get("text") in (None, "") else parse_text(body["text"])
    return ReplayParams(source, **parse_env(body), seed=parse_seed(body), text=text, settings=parse_sampling(body))


@dataclass(frozen=True)
class TimelineParams:
    """One ``POST /api/timeline``: segments (:class:`~simdiff.inference.timeline.Segment`), seed, sampling fields."""

    segments: tuple[Segment, ...]
    seed: int = 0
    settings: dict[str, Any] = field(default_factory=dict)

    def sampling(self) -> dict[str, Any]:
        """The sampling fields this request sets (the others are the model's)."""
        return {k: v for k, v in self.settings.items() if v is not None}


def parse_timeline_request(body: Any) -> TimelineParams:
    """Validate a ``POST /api/timeline`` body ``{segments: [{text, seconds, gravity?, wind?: [x, y]}, ...], seed,
    steps, eta, guidance, guidance_min_t, alpha, env_guidance, edit_t, foot_lock, flight_passes}``: the segments as ``generate --timeline``
    checks a file's (:func:`~simdiff.product.request.parse_timeline`, the same one-line messages), at most
    :data:`MAX_TIMELINE_SEGMENTS` of them."""
    check_fields(body, {"segments", "seed", *SAMPLING_FIELDS})
    segments = body.get("segments")
    if isinstance(segments, list) and len(segments) > MAX_TIMELINE_SEGMENTS:
        raise SimdiffError(f"the timeline has {len(segments)} segments; the viewer takes at most "
                           f"{MAX_TIMELINE_SEGMENTS} (simdiff generate --timeline takes more)")
    for i, segment in enumerate(segments if isinstance(segments, list) else []):
        if isinstance(segment, dict) and isinstance(segment.get("text"), str):
            _check_unicode(segment["text"], f"the timeline: segment {i}: text")
    return TimelineParams(parse_timeline(segments), parse_seed(body), parse_sampling(body))
