"""Validated parameters of one generation request (the viewer's sliders and prompt box).

Ranges match the ``simdiff generate`` CLI: gravity g_z ∈ [−20, −1] m/s², |wind| ≤ 10 N,
adapter strength α ∈ [0, 2], length 0.5 .. 9.8 s at 20 fps.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import asdict, dataclass
from typing import Any

from simdiff.errors import SimdiffError
from simdiff.motion.skeleton import FPS, MAX_FRAMES, MIN_GENERATE_FRAMES
from simdiff.product.request import MAX_PROMPT_CHARS, check_text
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


SAMPLING_FIELDS: tuple[str, ...] = ("steps", "eta", "guidance", "alpha", "env_guidance", "edit_t", "foot_lock")
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
        steps, eta, guidance, alpha, env_guidance, edit_t, foot_lock: the
            :class:`~simdiff.diffusion.config.SamplingConfig` fields, or None for the model's ``sampling.json``
            value, as ``simdiff generate``.
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
    foot_lock: float | None = None

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
        "env_guidance": list(ENV_GUIDANCE_RANGE), "edit_t": [0, 999],
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


def parse_generate(body: Any) -> GenerateParams:
    """Validate a ``POST /api/generate`` JSON body.

    Args:
        body: the decoded JSON object ``{text, gravity, wind_x, wind_y, seconds, seed, simulate, steps, eta,
            guidance, alpha, env_guidance, edit_t, foot_lock}``; everything but ``text`` is optional.
    Raises:
        SimdiffError: one line naming the bad field and value.
    """
    if not isinstance(body, dict):
        raise SimdiffError(f"request body must be a JSON object, got {type(body).__name__}")
    known = set(GenerateParams.__dataclass_fields__)
    unknown = sorted(set(body) - known)
    if unknown:
        raise SimdiffError(f"unknown field {_show(unknown[0])} (known: {', '.join(sorted(known))})")
    text = body.get("text")
    if not isinstance(text, str) or not text.strip():
        raise SimdiffError(f"text must be a non-empty prompt, got {_show(text)}")
    if not text.isascii():
        try:
            text.encode("utf-8")
        except UnicodeEncodeError:
            raise SimdiffError("text must be valid Unicode (it holds a lone surrogate escape)") from None
    text = check_text(text)
    defaults = GenerateParams(text=text)
    gravity = _number(body, "gravity", defaults.gravity)
    _check_range("gravity", gravity, *GRAVITY_RANGE, " m/s²")
    wind = {}
    for key in ("wind_x", "wind_y"):
        wind[key] = _number(body, key, 0.0)
        _check_range(key, wind[key], -MAX_WIND, MAX_WIND, " N")
    seconds = _number(body, "seconds", defaults.seconds)
    _check_range("seconds", seconds, MIN_SECONDS, MAX_SECONDS)
    seed = _integer(body, "seed", 0)
    if seed is None or not 0 <= seed < 2**63:
        raise SimdiffError(f"seed must be a non-negative integer below 2**63, got {_show(seed)}")
    simulate = body.get("simulate", False)
    if not isinstance(simulate, bool):
        raise SimdiffError(f"simulate must be true or false, got {_show(simulate)}")
    sampling: dict[str, Any] = {}
    for key, (low, high) in {"steps": (1, MAX_STEPS), "edit_t": (0, 999)}.items():
        value = _integer(body, key, None)
        if value is not None:
            _check_range(key, value, low, high)
        sampling[key] = value
    for key, (low, high) in {"eta": (0.0, 1.0), "guidance": GUIDANCE_RANGE, "alpha": ALPHA_RANGE,
                             "env_guidance": ENV_GUIDANCE_RANGE, "foot_lock": (0.0, 1.0)}.items():
        if body.get(key) is not None:
            sampling[key] = _number(body, key, 0.0)
            _check_range(key, sampling[key], low, high)
    return GenerateParams(text=text, gravity=gravity, seconds=seconds, seed=seed, simulate=simulate, **wind,
                          **sampling)
