"""Validated parameters of one generation request (the viewer's sliders and prompt box).

Ranges match the ``simdiff generate`` CLI: gravity g_z ∈ [−20, −1] m/s², |wind| ≤ 10 N,
adapter strength α ∈ [0, 2], length ≤ 9.8 s at 20 fps.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any, Mapping

from simdiff.errors import SimdiffError
from simdiff.product.request import MAX_PROMPT_CHARS, check_anchor, check_anchor_t_max, check_edit_t, check_text
from simdiff.motion.skeleton import FPS, MAX_FRAMES
from simdiff.sim.env import EARTH_GRAVITY, GRAVITY_RANGE, MAX_WIND

ALPHA_RANGE: tuple[float, float] = (0.0, 2.0)
"""Adapter strength α bounds (0 = backbone only, 1 = trained strength)."""
MAX_SECONDS: float = MAX_FRAMES / FPS
"""Longest motion in seconds (9.8 s)."""
MAX_STEPS: int = 200
"""Most DDIM steps a request from the page may ask for (the default is 50): one request holds the
model for at most about 4× a default generation, so a queue of them drains in bounded time."""
GUIDANCE_RANGE: tuple[float, float] = (0.0, 20.0)
"""Classifier-free guidance scale bounds."""
ENV_GUIDANCE_RANGE: tuple[float, float] = (0.0, 10.0)
"""Environment guidance s_e bounds (1 = off)."""
MAX_TEXT: int = MAX_PROMPT_CHARS
"""Longest prompt in characters (the same limit as ``simdiff generate``)."""


@dataclass(frozen=True)
class GenerateParams:
    """One generation: prompt, environment φ, adapter strength, length and sampler settings.

    Attributes:
        text: the prompt (stripped, non-empty).
        gravity: g_z in m/s² (Earth −9.81).
        wind_x, wind_y: horizontal wind force in newtons (HumanML3D +X, +Z).
        alpha: adapter strength α, or None for the model's ``sampling.json`` value (1 without one), as
            ``simdiff generate``.
        seconds: motion length in seconds (20 fps).
        seed: noise seed (≥ 0).
        steps: DDIM steps, or None for the sampler's default (50).
        guidance: classifier-free guidance scale.
        simulate: simulated finish: re-track the motion in the simulator under φ; the answer shows the
            simulated motion and carries the generated one and the tracking result in ``meta``.
        foot_lock: foot-lock strength in [0, 1] (:mod:`simdiff.motion.foot_lock`), or None for the model's
            ``sampling.json`` value (0 without one), as ``simdiff generate``.
        env_guidance: environment guidance s_e ≥ 0 (:mod:`simdiff.diffusion.guidance`), or None for the model's
            ``sampling.json`` value (1, off, without one).
        anchor: what the text guidance runs on, ``adapters``, ``backbone`` or ``reference``
            (:mod:`simdiff.diffusion.guidance`),
            or None for the model's ``sampling.json`` value (``adapters`` without one).
        env_guidance_fallback: s_e for a sample that floats or glides at ``env_guidance`` (re-sampled), or None for
            the model's ``sampling.json`` value (off without one).
        anchor_alpha: the backbone or reference anchor's adapter strength (:mod:`simdiff.diffusion.guidance`), or None
            for the model's ``sampling.json`` value when the anchor is the stored one (0 otherwise).
        anchor_t_max: that anchor only at timesteps ≤ this (0..999), or None for the model's ``sampling.json``
            value when the anchor is the stored one (every step otherwise).
        edit_t: the edit anchor's last timestep at Earth (0..999), or None for the model's ``sampling.json`` value when
            the anchor is the stored one (the sampler's default otherwise).
        ballistic: ballistic-flight strength in [0, 1] (:mod:`simdiff.motion.ballistic`), or None for the model's
            ``sampling.json`` value (0, off, without one).
        eta: DDIM's η in [0, 1] (0 deterministic, 1 fresh noise at every step), or None for the model's
            ``sampling.json`` value (0 without one).
    """

    text: str
    gravity: float = EARTH_GRAVITY
    wind_x: float = 0.0
    wind_y: float = 0.0
    alpha: float | None = None
    seconds: float = 6.0
    seed: int = 0
    steps: int | None = None
    guidance: float = 2.5
    simulate: bool = False
    foot_lock: float | None = None
    env_guidance: float | None = None
    anchor: str | None = None
    env_guidance_fallback: float | None = None
    anchor_alpha: float | None = None
    anchor_t_max: int | None = None
    edit_t: int | None = None
    ballistic: float | None = None
    eta: float | None = None

    @property
    def frames(self) -> int:
        """Motion length in frames at 20 fps (1..196)."""
        return max(1, min(MAX_FRAMES, round(self.seconds * FPS)))

    def as_dict(self) -> dict[str, Any]:
        """Plain JSON-able values."""
        return asdict(self)


def limits() -> dict[str, Any]:
    """The accepted ranges, for the page's sliders (units: m/s², N, s)."""
    return {
        "gravity": list(GRAVITY_RANGE), "wind": MAX_WIND, "alpha": list(ALPHA_RANGE), "seconds": MAX_SECONDS,
        "fps": FPS, "steps": MAX_STEPS, "guidance": list(GUIDANCE_RANGE), "text": MAX_TEXT,
        "env_guidance": list(ENV_GUIDANCE_RANGE), "env_guidance_fallback": list(ENV_GUIDANCE_RANGE),
    }


def _number(body: Mapping[str, Any], key: str, default: float) -> float:
    value = body.get(key, default)
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise SimdiffError(f"{key} must be a finite number, got {value!r}")
    return float(value)


def _integer(body: Mapping[str, Any], key: str, default: int | None) -> int | None:
    value = body.get(key, default)
    if value is None:
        return None
    if isinstance(value, float) and value.is_integer():
        value = int(value)
    if isinstance(value, bool) or not isinstance(value, int):
        raise SimdiffError(f"{key} must be an integer, got {value!r}")
    return value


def _check_range(key: str, value: float, low: float, high: float, unit: str = "") -> None:
    if not low <= value <= high:
        raise SimdiffError(f"{key} must be in [{low:g}, {high:g}]{unit}, got {value:g}")


def parse_generate(body: Any) -> GenerateParams:
    """Validate a ``POST /api/generate`` JSON body.

    Args:
        body: the decoded JSON object ``{text, gravity, wind_x, wind_y, alpha, seconds, seed, steps, guidance,
            simulate, foot_lock, env_guidance, anchor, env_guidance_fallback, anchor_alpha, anchor_t_max,
            edit_t, ballistic, eta}``;
            everything but ``text`` is optional.
    Raises:
        SimdiffError: one line naming the bad field and value.
    """
    if not isinstance(body, dict):
        raise SimdiffError(f"request body must be a JSON object, got {type(body).__name__}")
    known = set(GenerateParams.__dataclass_fields__)
    unknown = sorted(set(body) - known)
    if unknown:
        raise SimdiffError(f"unknown field {unknown[0]!r} (known: {', '.join(sorted(known))})")
    text = body.get("text")
    if not isinstance(text, str) or not text.strip():
        raise SimdiffError(f"text must be a non-empty prompt, got {str(text)[:40]!r}")
    text = check_text(text)
    defaults = GenerateParams(text=text)
    gravity = _number(body, "gravity", defaults.gravity)
    _check_range("gravity", gravity, *GRAVITY_RANGE, " m/s²")
    wind = {}
    for key in ("wind_x", "wind_y"):
        wind[key] = _number(body, key, 0.0)
        _check_range(key, wind[key], -MAX_WIND, MAX_WIND, " N")
    alpha = body.get("alpha")
    if alpha is not None:
        alpha = _number(body, "alpha", 1.0)
        _check_range("alpha", alpha, *ALPHA_RANGE)
    seconds = _number(body, "seconds", defaults.seconds)
    if not 1.0 / FPS <= seconds <= MAX_SECONDS:
        raise SimdiffError(f"seconds must be in [{1.0 / FPS:g}, {MAX_SECONDS:g}], got {seconds:g}")
    seed = _integer(body, "seed", 0)
    if seed is None or not 0 <= seed < 2**63:
        raise SimdiffError(f"seed must be a non-negative integer, got {seed!r}")
    steps = _integer(body, "steps", None)
    if steps is not None and not 1 <= steps <= MAX_STEPS:
        raise SimdiffError(f"steps must be in [1, {MAX_STEPS}], got {steps}")
    guidance = _number(body, "guidance", defaults.guidance)
    _check_range("guidance", guidance, *GUIDANCE_RANGE)
    simulate = body.get("simulate", False)
    if not isinstance(simulate, bool):
        raise SimdiffError(f"simulate must be true or false, got {simulate!r}")
    foot_lock = body.get("foot_lock")
    if foot_lock is not None:
        foot_lock = _number(body, "foot_lock", 0.0)
        _check_range("foot_lock", foot_lock, 0.0, 1.0)
    env_guidance = body.get("env_guidance")
    if env_guidance is not None:
        env_guidance = _number(body, "env_guidance", 1.0)
        _check_range("env_guidance", env_guidance, *ENV_GUIDANCE_RANGE)
    anchor = body.get("anchor")
    if anchor is not None:
        anchor = check_anchor("anchor", anchor)
    fallback = body.get("env_guidance_fallback")
    if fallback is not None:
        fallback = _number(body, "env_guidance_fallback", 1.0)
        _check_range("env_guidance_fallback", fallback, *ENV_GUIDANCE_RANGE)
    anchor_alpha = body.get("anchor_alpha")
    if anchor_alpha is not None:
        anchor_alpha = _number(body, "anchor_alpha", 0.0)
        _check_range("anchor_alpha", anchor_alpha, 0.0, ALPHA_RANGE[1])
    anchor_t_max = check_anchor_t_max("anchor_t_max", body.get("anchor_t_max"))
    edit_t = check_edit_t("edit_t", body.get("edit_t"))
    ballistic = body.get("ballistic")
    if ballistic is not None:
        ballistic = _number(body, "ballistic", 0.0)
        _check_range("ballistic", ballistic, 0.0, 1.0)
    eta = body.get("eta")
    if eta is not None:
        eta = _number(body, "eta", 0.0)
        _check_range("eta", eta, 0.0, 1.0)
    return GenerateParams(text=text, gravity=gravity, alpha=alpha, seconds=seconds, seed=seed, steps=steps,
                          guidance=guidance, simulate=simulate, foot_lock=foot_lock, env_guidance=env_guidance,
                          anchor=anchor, env_guidance_fallback=fallback, anchor_alpha=anchor_alpha,
                          anchor_t_max=anchor_t_max, edit_t=edit_t, ballistic=ballistic, eta=eta,
                          **wind)
