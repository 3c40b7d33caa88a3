"""Settings of the model check (issue 14's "done when" figures) and its fixed prompt lists."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from pathlib import Path

from simdiff.errors import SimdiffError

EARTH: tuple[float, float, float] = (-9.81, 0.0, 0.0)
MOON_G: float = -1.6
"""Low gravity of the physics-response check (m/s²)."""
WIND_N: float = 10.0
"""Wind strength of the drift check (N), along ±w_x and ±w_y."""
JUMP_PROMPTS: tuple[str, ...] = (
    "a person jumps forward",
    "a person jumps up in place",
    "a person hops on one leg",
    "a person jumps up and down",
    "a person hops forward on both feet",
    "a person does a long jump",
)
"""Prompts that ask for a jump or a hop."""
SPEED_PROMPTS: dict[str, tuple[str, ...]] = {
    "walk": ("a person walks forward", "a person is walking straight ahead"),
    "run": ("a person runs forward", "a person jogs forward"),
}
"""Prompts per corpus ``motion_type`` whose speed is compared with that type's train clips."""


@dataclass
class SplitOptions:
    """The test-split protocol (:func:`simdiff.eval.protocol.evaluate_t2m`, one replication per seed).

    Attributes:
        split: corpus split (``test``); n: motions per replication (the whole split when smaller);
        batch_size: R-precision batch (32; smaller only when n < 32, as in ``--quick``).
    """

    split: str = "test"
    n: int = 256
    batch_size: int = 32


@dataclass
class PromptOptions:
    """Jump/hop and walk/run prompt checks.

    Attributes:
        jump_samples: samples per jump prompt, split over the seeds.
        speed_samples: samples per walk/run prompt, split over the seeds.
        length: frames per sample (20 fps).
        corpus_clips: most train clips per motion type read for the corpus speeds (0: all).
    """

    jump_samples: int = 32
    speed_samples: int = 16
    length: int = 120
    corpus_clips: int = 0


@dataclass
class ResponseOptions:
    """Physics response (models with a Sim Encoder only).

    Attributes:
        enabled: run it when the model is a continuous SimDiff model.
        workers: simulator processes (0: all cores); residual_bound: tracker root-residual bound
            (fraction of m·|g_z|, as the experiments use).
        resamples: bootstrap resamples of the response scores.
    """

    enabled: bool = True
    workers: int = 0
    residual_bound: float = 0.5
    resamples: int = 1000


@dataclass
class CheckConfig:
    """One model check.

    Attributes:
        model, corpus, evaluator: folders (model: ``model.safetensors`` + ``config.json``; corpus in the
            HumanML3D layout, ``manifest.json`` with ``motion_type`` for the speed check; evaluator:
            :func:`simdiff.eval.evaluator.save_evaluator` output).
        out: report folder (``check.json``, ``check.md``, ``parts/``).
        seeds: one protocol replication per seed; the prompt checks split their samples over them.
        steps: DDIM steps; guidance: CFG scale; alpha: adapter strength of SimDiff models; foot_lock: the
            generator's foot-lock strength (0: off, :mod:`simdiff.motion.foot_lock`); env_guidance: environment
            guidance s_e (1: off, :mod:`simdiff.diffusion.guidance`; changes only motions generated off Earth);
            anchor: what the text guidance runs on, ``adapters``, ``backbone``, ``reference`` or ``edit``
            (:mod:`simdiff.diffusion.guidance`);
            anchor_alpha: the backbone or reference anchor's adapter strength (0: the backbone alone);
            anchor_t_max: that anchor only at timesteps ≤ this, the adapters anchor above (None: every step);
            edit_t: with the ``edit`` anchor, its last timestep at Earth (None: its default);
            eta: the DDIM sampler's η in [0, 1] (0: deterministic, the default; 1: about DDPM's noise);
            env_guidance_fallback: s_e for the prompt samples that float or glide at ``env_guidance`` (re-sampled;
            None: off). The test split is generated at Earth without wind, where any s_e gives the same motion.
            ballistic: strength in [0, 1] of the generator's ballistic flight (:mod:`simdiff.motion.ballistic`; 0: off),
            applied to every motion the check generates, the test split's included.
        more_evaluators: further evaluator folders that score the same test-split motions (each motion generated
            once); the verdicts use ``evaluator``. FID differences between models or settings depend on which
            evaluator was trained (session 47), so a claimed FID change should hold under a second one.
        device: torch device; quick: the smoke preset was applied (reported).
    """

    model: str
    corpus: str
    evaluator: str
    out: str
    seeds: list[int] = field(default_factory=lambda: [0, 1, 2, 3, 4])
    steps: int = 50
    guidance: float = 2.5
    alpha: float = 1.0
    foot_lock: float = 0.0
    env_guidance: float = 1.0
    anchor: str = "adapters"
    env_guidance_fallback: float | None = None
    anchor_alpha: float = 0.0
    anchor_t_max: int | None = None
    edit_t: int | None = None
    eta: float = 0.0
    ballistic: float = 0.0
    more_evaluators: list[str] = field(default_factory=list)
    device: str = "cpu"
    quick: bool = False
    split: SplitOptions = field(default_factory=SplitOptions)
    prompts: PromptOptions = field(default_factory=PromptOptions)
    response: ResponseOptions = field(default_factory=ResponseOptions)

    def as_dict(self) -> dict:
        return dataclasses.asdict(self)

    def validate(self) -> "CheckConfig":
        """Check values and that the three input folders hold what the check reads; returns self."""
        if not self.seeds:
            raise SimdiffError("give at least one seed (--seeds)")
        if len(set(self.seeds)) != len(self.seeds):
            raise SimdiffError(f"--seeds must be distinct, got {self.seeds}")
        for name, value, low in (("--n", self.split.n, 2), ("--steps", self.steps, 1),
                                 ("--jump-samples", self.prompts.jump_samples, 1),
                                 ("--speed-samples", self.prompts.speed_samples, 1), ("--length", self.prompts.length, 8)):
            if value < low:
                raise SimdiffError(f"{name} must be at least {low}, got {value}")
        if not 0.0 <= self.foot_lock <= 1.0:
            raise SimdiffError(f"--foot-lock must be in [0, 1], got {self.foot_lock}")
        if not 0.0 <= self.eta <= 1.0:
            raise SimdiffError(f"--eta must be in [0, 1], got {self.eta}")
        if not 0.0 <= self.ballistic <= 1.0:
            raise SimdiffError(f"--ballistic must be in [0, 1], got {self.ballistic}")
        if not 0.0 <= self.env_guidance < float("inf"):
            raise SimdiffError(f"--env-guidance must be a finite number ≥ 0, got {self.env_guidance}")
        if self.env_guidance_fallback is not None and not 0.0 <= self.env_guidance_fallback < float("inf"):
            raise SimdiffError(f"--env-guidance-fallback must be a finite number ≥ 0, got {self.env_guidance_fallback}")
        from simdiff.diffusion.guidance import ANCHORS, check_anchor_alpha, check_anchor_t_max, check_edit_t

        if self.anchor not in ANCHORS:
            raise SimdiffError(f"--anchor must be one of {', '.join(ANCHORS)}, got {self.anchor!r}")
        self.anchor_alpha = check_anchor_alpha(self.anchor_alpha, self.anchor)
        self.anchor_t_max = check_anchor_t_max(self.anchor_t_max, self.anchor)
        if self.edit_t is not None:
            self.edit_t = check_edit_t(self.edit_t, self.anchor)
        if self.prompts.length > 196:
            raise SimdiffError(f"--length must be at most 196 frames, got {self.prompts.length}")
        model, corpus, evaluator = Path(self.model), Path(self.corpus), Path(self.evaluator)
        for path in (model / "model.safetensors", model / "config.json"):
            if not path.is_file():
                raise SimdiffError(f"model folder {model}: missing {path.name}")
        if not (corpus / f"{self.split.split}.txt").is_file():
            raise SimdiffError(f"corpus {corpus}: no {self.split.split}.txt (give a HumanML3D-layout corpus)")
        for folder in [evaluator, *map(Path, self.more_evaluators)]:
            if not (folder / "model.safetensors").is_file():
                raise SimdiffError(f"evaluator folder {folder}: missing model.safetensors")
        if len({Path(e).resolve() for e in [evaluator, *self.more_evaluators]}) != 1 + len(self.more_evaluators):
            raise SimdiffError(f"evaluators must be distinct folders, got {[str(evaluator), *self.more_evaluators]}")
        return self


def quick_preset(config: CheckConfig) -> CheckConfig:
    """The smoke preset: n = 16, one seed, ≤ 10 DDIM steps, ≤ 4 samples per prompt, ≤ 80 frames, 200 corpus
    clips per motion type, 100 bootstrap resamples."""
    return dataclasses.replace(
        config, seeds=config.seeds[:1], steps=min(config.steps, 10), quick=True,
        split=dataclasses.replace(config.split, n=16, batch_size=16),
        prompts=dataclasses.replace(config.prompts, jump_samples=min(config.prompts.jump_samples, 4),
                                    speed_samples=min(config.prompts.speed_samples, 4),
                                    length=min(config.prompts.length, 80), corpus_clips=200),
        response=dataclasses.replace(config.response, resamples=100))
