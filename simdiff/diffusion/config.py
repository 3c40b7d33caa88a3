"""One sampling configuration: the schema of a model's ``sampling.json`` and of every sampling option.

Pure Python (no torch), so the command line can read a model's values to show them as its defaults.
"""

from __future__ import annotations

import json
import math
import os
from dataclasses import asdict, dataclass, fields, replace
from typing import Any

from simdiff.errors import SimdiffError

SAMPLERS: tuple[str, ...] = ("ddim", "ddpm")
"""``--sampler`` values."""
SAMPLER_STEPS: dict[str, int] = {"ddim": 50, "ddpm": 1000}
"""Each sampler's steps when a configuration switches to it without giving them."""
MAX_STEPS: int = 1000
"""Diffusion steps the models are trained with (the most a sampler can take)."""
GUIDANCE_RANGE: tuple[float, float] = (0.0, 20.0)
"""Classifier-free guidance scales accepted (the shipped model samples at 3; a bound against typing slips)."""
ALPHA_RANGE: tuple[float, float] = (-2.0, 4.0)
"""Adapter strengths accepted (0: backbone only, 1: as trained)."""
ENV_GUIDANCE_RANGE: tuple[float, float] = (0.0, 10.0)
"""Environment guidance scales accepted (1: off)."""
MAX_SEED: int = 2**32 - 1
"""Largest ``--seed`` a command accepts (numpy's seed range)."""
MAX_FLIGHT_PASSES: int = 10
"""Most flight-guidance passes per denoising step (three bring every flight within 1 cm of its parabola)."""


@dataclass(frozen=True)
class SamplingConfig:
    """How motions are sampled, validated on construction (one-line :class:`SimdiffError` naming the option).

    Attributes:
        sampler: ``ddim`` or ``ddpm``.
        steps: denoising steps, 1..1000.
        eta: DDIM's η in [0, 1] (0: deterministic; 1: fresh noise at every step); 0 with DDPM.
        guidance: classifier-free guidance scale s ≥ 0 (1: off).
        guidance_min_t: the text guidance runs at timesteps ≥ this (0..999) and the conditional prediction alone
            below it, one network pass instead of two (0: guidance at every step).
        alpha: adapter strength α of SimDiff models (0: backbone only).
        env_guidance: environment guidance s_e ≥ 0 (1: off); continuous-φ models only.
        edit_t: the last timestep (0..999) at which a motion under another gravity than Earth's still follows its
            Earth motion (continuous-φ models; :mod:`simdiff.diffusion.guidance`).
        foot_lock: strength in [0, 1] of the foot cleanup applied to the final sample (0: off).
        flight_passes: flight guidance, 0..10 passes per denoising step at and below ``edit_t`` that bend every
            flight of x̂₀ onto a parabola of the requested gravity (0: off; :mod:`simdiff.inference.flight_guidance`).
    """

    sampler: str = "ddim"
    steps: int = 50
    eta: float = 0.0
    guidance: float = 2.5
    guidance_min_t: int = 0
    alpha: float = 1.0
    env_guidance: float = 1.0
    edit_t: int = 950
    foot_lock: float = 0.0
    flight_passes: int = 0

    def __post_init__(self) -> None:
        if self.sampler not in SAMPLERS:
            raise SimdiffError(f"--sampler must be one of {', '.join(SAMPLERS)}, got {self.sampler!r}")
        set_ = object.__setattr__
        set_(self, "steps", _whole("--steps", self.steps, 1, MAX_STEPS))
        set_(self, "eta", _number("--eta", self.eta, 0.0, 1.0))
        if self.eta and self.sampler != "ddim":
            raise SimdiffError(f"--eta {self.eta:g} is DDIM's noise scale; it needs --sampler ddim, "
                               f"not {self.sampler!r}")
        set_(self, "guidance", _number("--guidance", self.guidance, *GUIDANCE_RANGE))
        set_(self, "alpha", _number("--alpha", self.alpha, *ALPHA_RANGE))
        set_(self, "env_guidance", _number("--env-guidance", self.env_guidance, *ENV_GUIDANCE_RANGE))
        set_(self, "guidance_min_t", _whole("--guidance-min-t", self.guidance_min_t, 0, 999))
        set_(self, "edit_t", _whole("--edit-t", self.edit_t, 0, 999))
        set_(self, "foot_lock", _number("--foot-lock", self.foot_lock, 0.0, 1.0))
        set_(self, "flight_passes", _whole("--flight-passes", self.flight_passes, 0, MAX_FLIGHT_PASSES))

    def updated(self, **given: Any) -> "SamplingConfig":
        """A copy with the options in ``given`` that are not None (checked). Switching the sampler without giving
        ``steps``, ``eta`` or ``guidance_min_t`` takes the new sampler's steps (:data:`SAMPLER_STEPS`), η 0 and
        guidance at every step."""
        given = {k: v for k, v in given.items() if v is not None}
        sampler = given.get("sampler", self.sampler)
        if sampler != self.sampler:
            given.setdefault("steps", SAMPLER_STEPS.get(sampler, self.steps))
            given.setdefault("eta", 0.0)
            given.setdefault("guidance_min_t", 0)
        return replace(self, **given)

    def to_dict(self) -> dict[str, Any]:
        """The ``sampling.json`` object."""
        return asdict(self)

    @classmethod
    def from_dict(cls, data: object, origin: str = "sampling.json") -> "SamplingConfig":
        """A configuration from a ``sampling.json`` object (missing keys: the class defaults).

        Raises:
            SimdiffError: not an object, an unknown key or a bad value (one line naming ``origin``, key and value).
        """
        if not isinstance(data, dict):
            raise SimdiffError(f"{origin}: expected a JSON object such as {{\"guidance\": 3.0}}")
        names = [f.name for f in fields(cls)]
        for key, value in data.items():
            if key not in names:
                raise SimdiffError(f"{origin}: unknown key {key!r} = {value!r}; allowed: {', '.join(names)}")
            if isinstance(value, bool) or not isinstance(value, (str, int, float)):
                raise SimdiffError(f"{origin}: {key} = {value!r} is not a number or a name")
        try:
            return cls(**data)
        except SimdiffError as exc:
            raise SimdiffError(f"{origin}: {exc}") from None

    @classmethod
    def read(cls, path: str | os.PathLike[str]) -> "SamplingConfig":
        """The configuration stored in the ``sampling.json`` at ``path``."""
        try:
            with open(path, encoding="utf-8") as f:
                data = json.load(f)
        except (OSError, ValueError) as exc:
            raise SimdiffError(f"{path}: cannot read sampling settings: {str(exc).splitlines()[0]}") from None
        return cls.from_dict(data, str(path))


def _number(name: str, value: object, lo: float | None = None, hi: float | None = None) -> float:
    """``value`` as a finite float in [lo, hi], else a one-line :class:`SimdiffError` naming ``name``."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise SimdiffError(f"{name} must be a finite number, got {value!r}")
    if (lo is not None and value < lo) or (hi is not None and value > hi):
        span = f"in [{lo:g}, {hi:g}]" if hi is not None else f"≥ {lo:g}"
        raise SimdiffError(f"{name} must be {span}, got {value:g}")
    return float(value)


def _whole(name: str, value: object, lo: int, hi: int) -> int:
    """``value`` as an int in [lo, hi], else a one-line :class:`SimdiffError` naming ``name``."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) \
            or value != int(value) or not lo <= value <= hi:
        raise SimdiffError(f"{name} must be a whole number in {lo}..{hi}, got {value!r}")
    return int(value)
