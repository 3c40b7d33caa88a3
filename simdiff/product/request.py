"""A checked generation request: what ``simdiff generate`` validates before loading any model.

Pure Python + numpy (no torch), so bad input fails in milliseconds with one line naming the value.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from simdiff.errors import SimdiffError
from simdiff.motion.skeleton import FPS, MAX_FRAMES
from simdiff.sim.env import EARTH_GRAVITY, Environment

MAX_STEPS: int = 1000
"""Diffusion steps the models are trained with (the most a sampler can take)."""
MAX_SAMPLES: int = 64
"""Most samples per run (each is sampled, written and rendered)."""
MAX_COMPARE: int = 8
"""Most environments in one ``--compare`` video."""
COMPARE_KEYS: tuple[str, ...] = ("gravity", "wind_x", "wind_y")
"""Environment components ``--compare`` can vary."""
FORMATS: tuple[str, ...] = ("npy", "bvh", "gif", "mp4")
"""Output kinds: ``npy`` = joints + features, ``bvh``, and the ``gif``/``mp4`` stick video."""
DEFAULT_FORMATS: tuple[str, ...] = ("npy", "bvh", "gif")
VIDEO_FORMATS: tuple[str, ...] = ("gif", "mp4")
SAMPLER_DEFAULT_STEPS: dict[str, int] = {"ddim": 50, "ddpm": 1000}
MAX_PROMPT_CHARS: int = 500
"""Longest prompt in characters (after collapsing white space), for the CLI and the viewer alike."""


@dataclass(frozen=True)
class GenerationRequest:
    """Everything one ``simdiff generate`` run does, already validated.

    Attributes:
        text: the prompt (stripped, non-empty).
        frames: motion length in frames at 20 fps, 1..196.
        envs: the environments φ to generate under: one, or several for ``--compare``.
        compare: the φ component varied across ``envs`` (``gravity``, ``wind_x``, ``wind_y``) or None.
        seed: noise seed of sample 0; sample k uses ``seed + k`` (the same under every environment).
        num_samples: samples per environment.
        sampler: ``ddim`` or ``ddpm``.
        steps: diffusion steps.
        eta: DDIM's η in [0, 1] (0: deterministic; 1: fresh noise at every step, as DDPM); 0 with DDPM.
        guidance: classifier-free guidance scale (1 = off).
        alpha: adapter strength α (0 = backbone only).
        foot_lock: foot-lock strength in [0, 1] (0: off; :mod:`simdiff.motion.foot_lock`).
        env_guidance: environment guidance s_e ≥ 0 (1: off; :mod:`simdiff.diffusion.guidance`).
        env_guidance_fallback: s_e ≥ 0 for samples that come out floating or gliding at ``env_guidance``
            (re-sampled with the same seed; None: off; :meth:`simdiff.model.generator.MotionGenerator.generate`).
        anchor: what the text guidance runs on, ``adapters``, ``backbone``, ``reference`` or ``edit``
            (:data:`ANCHORS`).
        anchor_alpha: with the ``backbone``, ``reference`` or ``edit`` anchor, the adapter strength its text guidance runs at
            (0: the backbone alone; :mod:`simdiff.diffusion.guidance`).
        anchor_t_max: with the ``backbone`` or ``reference`` anchor, the last timestep (0..999) it runs at from
            below, the adapters anchor at the earlier steps (None: every step).
        edit_t: with the ``edit`` anchor, the last timestep (0..999) at which a motion under another gravity
            still follows its Earth motion (None: the model's or the sampler's default).
        ballistic: ballistic-flight strength in [0, 1] (0: off; :mod:`simdiff.motion.ballistic`): flights follow the
            parabola of the sample's gravity.
        formats: output kinds, a subset of :data:`FORMATS`.
        force: environments outside the trained range were allowed.
    """

    text: str
    frames: int = 120
    envs: tuple[Environment, ...] = (Environment(),)
    compare: str | None = None
    seed: int = 0
    num_samples: int = 1
    sampler: str = "ddim"
    steps: int = 50
    eta: float = 0.0
    guidance: float = 2.5
    alpha: float = 1.0
    foot_lock: float = 0.0
    env_guidance: float = 1.0
    env_guidance_fallback: float | None = None
    anchor: str = "adapters"
    anchor_alpha: float = 0.0
    anchor_t_max: int | None = None
    edit_t: int | None = None
    ballistic: float = 0.0
    formats: tuple[str, ...] = DEFAULT_FORMATS
    force: bool = False

    @property
    def seconds(self) -> float:
        """Motion length in seconds."""
        return self.frames / FPS

    @property
    def video_formats(self) -> tuple[str, ...]:
        """The requested video kinds (``gif``, ``mp4``), possibly none."""
        return tuple(f for f in self.formats if f in VIDEO_FORMATS)

    def with_envs(self, envs: tuple[Environment, ...]) -> "GenerationRequest":
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


def frames_from(length_s: float | None = None, frames: int | None = None, default: int = 120) -> int:
    """Frames at 20 fps from ``--length SECONDS`` or ``--frames N`` (at most one given).

    Raises:
        SimdiffError: both given, non-finite, or outside 1..196 frames (0.05..9.8 s).
    """
    if length_s is not None and frames is not None:
        raise SimdiffError(f"give --length ({length_s} s) or --frames ({frames}), not both")
    if length_s is not None:
        if not math.isfinite(length_s):
            raise SimdiffError(f"--length must be a number of seconds, got {length_s}")
        n = int(round(length_s * FPS))
        if not 1 <= n <= MAX_FRAMES:
            raise SimdiffError(f"--length {length_s:g} s is {n} frames; it must be 1..{MAX_FRAMES} frames "
                               f"({1 / FPS:g}..{MAX_FRAMES / FPS:g} s at {FPS} fps)")
        return n
    n = default if frames is None else int(frames)
    if not 1 <= n <= MAX_FRAMES:
        raise SimdiffError(f"--frames must be 1..{MAX_FRAMES} ({MAX_FRAMES / FPS:g} s at {FPS} fps), got {n}")
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


def parse_formats(spec: str | None, no_video: bool = False) -> tuple[str, ...]:
    """``"npy,bvh,gif"`` → ``("npy", "bvh", "gif")``; ``no_video`` drops gif/mp4.

    Raises:
        SimdiffError: an unknown kind, or nothing left to write.
    """
    kinds = DEFAULT_FORMATS if spec is None else tuple(dict.fromkeys(k.strip().lower() for k in spec.split(",") if k.strip()))
    bad = [k for k in kinds if k not in FORMATS]
    if bad:
        raise SimdiffError(f"unknown --format {bad[0]!r}; choose from {', '.join(FORMATS)} (comma-separated)")
    if no_video:
        kinds = tuple(k for k in kinds if k not in VIDEO_FORMATS)
    if not kinds:
        raise SimdiffError("nothing to write: --format is empty (or only video with --no-video)")
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


def steps_for(sampler: str, steps: int | None) -> int:
    """Diffusion steps: ``steps`` or the sampler's default (DDIM 50, DDPM 1000), checked in 1..1000."""
    if sampler not in SAMPLER_DEFAULT_STEPS:
        raise SimdiffError(f"unknown sampler {sampler!r}; choose ddim or ddpm")
    n = SAMPLER_DEFAULT_STEPS[sampler] if steps is None else int(steps)
    if not 1 <= n <= MAX_STEPS:
        raise SimdiffError(f"--steps must be 1..{MAX_STEPS}, got {n}")
    return n


def check_finite(name: str, value: float, minimum: float | None = None) -> float:
    """``value`` as float if finite (and ≥ ``minimum``); else a one-line error naming ``name``."""
    value = float(value)
    if not math.isfinite(value):
        raise SimdiffError(f"{name} must be a finite number, got {value}")
    if minimum is not None and value < minimum:
        raise SimdiffError(f"{name} must be ≥ {minimum:g}, got {value:g}")
    return value


STORED_NUMBERS: tuple[str, ...] = ("guidance", "alpha", "foot_lock", "env_guidance", "ballistic")
"""The numeric ``sampling.json`` settings."""

ANCHORS: tuple[str, ...] = ("adapters", "backbone", "reference", "edit")
"""``--anchor`` values: :data:`simdiff.diffusion.guidance.ANCHORS` (repeated here, where torch is not imported)."""

ALPHA_ANCHORS: tuple[str, ...] = ("backbone", "reference", "edit")
"""The anchors that take ``--anchor-alpha`` (:data:`simdiff.diffusion.guidance.ALPHA_ANCHORS`)."""

DEFAULT_EDIT_T: int = 800
"""The edit anchor's last timestep at Earth unless told (:data:`simdiff.diffusion.guidance.DEFAULT_EDIT_T`)."""

T_MAX_ANCHORS: tuple[str, ...] = ("backbone", "reference")
"""The anchors that take ``--anchor-t-max`` (:data:`simdiff.diffusion.guidance.T_MAX_ANCHORS`)."""


def check_eta(name: str, value: object, sampler: str) -> float:
    """``value`` as a float in [0, 1], and 0 unless ``sampler`` is ``ddim`` (one-line errors naming ``name``)."""
    number = check_unit(name, value)
    if number and sampler != "ddim":
        raise SimdiffError(f"{name} {number:g} is DDIM's noise scale; it needs --sampler ddim, not {sampler!r}")
    return number


def stored_eta(stored: dict[str, float | int | str], sampler: str) -> float:
    """A model's stored ``eta`` when ``sampler`` is its stored sampler (the value belongs to DDIM), else 0; checked
    as the option is."""
    if sampler != stored.get("sampler", "ddim"):
        return 0.0
    return check_eta("eta", stored.get("eta", 0.0), sampler)


def check_anchor(name: str, value: object) -> str:
    """``value`` if it is one of :data:`ANCHORS`, else a one-line error naming ``name``."""
    if value not in ANCHORS:
        raise SimdiffError(f"{name} must be one of {', '.join(ANCHORS)}, got {value!r}")
    return str(value)


def check_anchor_alpha(name: str, value: object, anchor: str) -> float:
    """``value`` as a finite float ≥ 0, and 0 unless ``anchor`` is ``backbone``, ``reference`` or ``edit`` (one-line
    errors naming ``name``)."""
    number = check_finite(name, value, 0.0)
    if number and anchor not in ALPHA_ANCHORS:
        raise SimdiffError(f"{name} {number:g} needs the backbone, reference or edit anchor (--anchor backbone, "
                           f"reference or edit), not {anchor!r}")
    return number


def whole_timestep(name: str, value: object) -> int:
    """``value`` as an int in [0, 999], else a one-line error naming ``name``."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or value != value or value != int(value) \
            or not 0 <= value <= 999:
        raise SimdiffError(f"{name} must be a whole timestep in 0..999, got {value!r}")
    return int(value)


def check_anchor_t_max(name: str, value: object, anchor: str | None = None) -> int | None:
    """``value`` as a whole timestep in [0, 999] (None passes), usable with ``anchor`` unless that is None (the
    ``backbone`` or ``reference`` anchor); one-line errors naming ``name``."""
    if value is None:
        return None
    value = whole_timestep(name, value)
    if anchor is not None and anchor not in T_MAX_ANCHORS:
        raise SimdiffError(f"{name} {int(value)} needs the backbone or reference anchor (--anchor backbone or "
                           f"reference), not {anchor!r}")
    return int(value)


def check_edit_t(name: str, value: object, anchor: str | None = None) -> int | None:
    """``value`` as a whole timestep in [0, 999] (None passes), usable with ``anchor`` unless that is None (the
    ``edit`` anchor); one-line errors naming ``name``."""
    if value is None:
        return None
    value = whole_timestep(name, value)
    if anchor is not None and anchor != "edit":
        raise SimdiffError(f"{name} {int(value)} needs the edit anchor (--anchor edit), not {anchor!r}")
    return int(value)


def stored_edit_t(stored: dict[str, float | int | str], anchor: str) -> int | None:
    """A model's stored ``edit_t`` when ``anchor`` is its stored anchor (the value belongs to that anchor), else None;
    checked as the option is."""
    if anchor != stored.get("anchor", "adapters"):
        return None
    return check_edit_t("edit_t", stored.get("edit_t"), anchor)


def stored_anchor_t_max(stored: dict[str, float | int | str], anchor: str) -> int | None:
    """A model's stored ``anchor_t_max`` when ``anchor`` is its stored anchor (the value belongs to that anchor),
    else None; checked as the option is."""
    if anchor != stored.get("anchor", "adapters"):
        return None
    return check_anchor_t_max("anchor_t_max", stored.get("anchor_t_max"), anchor)


def stored_anchor_alpha(stored: dict[str, float | int | str], anchor: str) -> float:
    """A model's stored ``anchor_alpha`` when ``anchor`` is its stored anchor (the value belongs to that anchor), else
    0; checked as the option is (one-line errors naming it)."""
    if anchor != stored.get("anchor", "adapters"):
        return 0.0
    return check_anchor_alpha("anchor_alpha", stored.get("anchor_alpha", 0.0), anchor)


def with_model_defaults(request: GenerationRequest, stored: dict[str, float | int | str],
                        given: set[str]) -> GenerationRequest:
    """Apply a model's stored sampling settings (``sampling.json``) to the options the user did not give.

    Args:
        stored: any of ``sampler``, ``steps``, ``guidance``, ``alpha``, ``foot_lock``, ``env_guidance``,
            ``env_guidance_fallback``,
            ``anchor``, ``anchor_alpha``, ``anchor_t_max``, ``edit_t``, ``ballistic``, ``eta`` (see
            :func:`simdiff.model.default.sampling_defaults`).
        given: option names the user set explicitly (``sampler``, ``steps``, ``guidance``, ``alpha``,
            ``foot_lock``, ``env_guidance``, ``env_guidance_fallback``, ``anchor``, ``anchor_alpha``,
            ``anchor_t_max``, ``edit_t``, ``ballistic``, ``eta``). A stored ``anchor_alpha``, ``anchor_t_max`` or
            ``edit_t`` belongs to the stored anchor, a stored ``eta`` to the stored sampler: it is dropped when the user
            picks another anchor (sampler).
    """
    sampler = request.sampler if "sampler" in given else str(stored.get("sampler", request.sampler))
    if "steps" in given:
        steps = request.steps
    elif "sampler" in given and sampler != stored.get("sampler", sampler):
        steps = steps_for(sampler, None)
    else:
        steps = steps_for(sampler, stored.get("steps"))  # type: ignore[arg-type]
    anchor = request.anchor if "anchor" in given else check_anchor("anchor", stored.get("anchor", request.anchor))
    anchor_alpha = (check_anchor_alpha("--anchor-alpha", request.anchor_alpha, anchor) if "anchor_alpha" in given
                    else stored_anchor_alpha(stored, anchor))
    anchor_t_max = (check_anchor_t_max("--anchor-t-max", request.anchor_t_max, anchor) if "anchor_t_max" in given
                    else stored_anchor_t_max(stored, anchor))
    edit_t = (check_edit_t("--edit-t", request.edit_t, anchor) if "edit_t" in given else stored_edit_t(stored, anchor))
    eta = check_eta("--eta", request.eta, sampler) if "eta" in given else stored_eta(stored, sampler)
    fallback = request.env_guidance_fallback
    if "env_guidance_fallback" not in given and stored.get("env_guidance_fallback") is not None:
        fallback = check_finite("env_guidance_fallback", stored["env_guidance_fallback"], 0.0)
    return replace(
        request, sampler=sampler, steps=steps, eta=eta, anchor=anchor, anchor_alpha=anchor_alpha,
        anchor_t_max=anchor_t_max,
        edit_t=edit_t, env_guidance_fallback=fallback,
        **{name: getattr(request, name) if name in given else stored_setting(stored, name, getattr(request, name))
           for name in STORED_NUMBERS},
    )


def stored_setting(stored: dict[str, float | int | str], name: str, default: float) -> float:
    """A model's stored value of the numeric setting ``name`` (``default`` when it has none), checked as the
    option is: ``foot_lock`` and ``ballistic`` in [0, 1], ``alpha`` finite, the others finite and ≥ 0 (one-line
    errors naming it)."""
    value = stored.get(name, default)
    if name in ("foot_lock", "ballistic"):
        return check_unit(name, value)
    return check_finite(name, value, None if name == "alpha" else 0.0)  # type: ignore[arg-type]


def check_unit(name: str, value: object) -> float:
    """``value`` as a float in [0, 1], else a one-line error naming it."""
    number = check_finite(name, value, 0.0)
    if number > 1.0:
        raise SimdiffError(f"{name} must be in [0, 1], got {number:g}")
    return number


def build_request(text: str, *, gravity: float | None = None, wind: tuple[float, float] | None = None,
                  length_s: float | None = None, frames: int | None = None, seed: int = 0, num_samples: int = 1,
                  sampler: str = "ddim", steps: int | None = None, guidance: float = 2.5, alpha: float = 1.0,
                  foot_lock: float = 0.0, env_guidance: float = 1.0, anchor: str = "adapters",
                  env_guidance_fallback: float | None = None, anchor_alpha: float = 0.0,
                  anchor_t_max: int | None = None, ballistic: float = 0.0, compare: str | None = None,
                  edit_t: int | None = None, eta: float = 0.0,
                  formats: str | None = None,
                  no_video: bool = False, force: bool = False) -> GenerationRequest:
    """Validate every user option and return the request (raises :class:`SimdiffError` on the first bad one)."""
    if seed < 0:
        raise SimdiffError(f"--seed must be ≥ 0, got {seed}")
    if not 1 <= num_samples <= MAX_SAMPLES:
        raise SimdiffError(f"--num-samples must be 1..{MAX_SAMPLES}, got {num_samples}")
    spec = parse_compare(compare) if compare is not None else None
    return GenerationRequest(
        text=check_text(text),
        frames=frames_from(length_s, frames),
        envs=environments(EARTH_GRAVITY if gravity is None else gravity, (0.0, 0.0) if wind is None else tuple(wind),
                          spec, force),
        compare=spec[0] if spec else None,
        seed=int(seed),
        num_samples=int(num_samples),
        sampler=sampler,
        steps=steps_for(sampler, steps),
        eta=check_eta("--eta", eta, sampler),
        guidance=check_finite("--guidance", guidance, 0.0),
        alpha=check_finite("--alpha", alpha),
        foot_lock=check_unit("--foot-lock", foot_lock),
        env_guidance=check_finite("--env-guidance", env_guidance, 0.0),
        env_guidance_fallback=(None if env_guidance_fallback is None
                               else check_finite("--env-guidance-fallback", env_guidance_fallback, 0.0)),
        anchor=check_anchor("--anchor", anchor),
        anchor_alpha=check_finite("--anchor-alpha", anchor_alpha, 0.0),
        anchor_t_max=check_anchor_t_max("--anchor-t-max", anchor_t_max),
        edit_t=check_edit_t("--edit-t", edit_t),
        ballistic=check_unit("--ballistic", ballistic),
        formats=parse_formats(formats, no_video),
        force=bool(force),
    )
