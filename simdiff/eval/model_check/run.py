"""Run a model check: load once, measure each section (cached in ``parts/``), write check.json + check.md.

Sections (see the package docstring): ``test_split``, ``jumps``, ``speeds`` and, for continuous
SimDiff models, ``response`` (gravity on the jump prompts and, without a verdict, on the run
prompts; wind). Each section's result is stored atomically in ``<out>/parts/<section>.json`` with a fingerprint of everything that determines it (model file
stamp, settings, corpus, evaluator); a rerun reuses a part whose fingerprint matches, so an
interrupted check resumes after its last finished section.
"""

from __future__ import annotations

import hashlib
import json
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from simdiff.errors import SimdiffError
from simdiff.eval.model_check.config import EARTH, JUMP_PROMPTS, MOON_G, SPEED_PROMPTS, WIND_N, CheckConfig
from simdiff.eval.model_check.samples import PromptBatch, generate_set_flags, plan_batches, units
from simdiff.motion.foot_lock import CLEANUP_VERSION
from simdiff.motion.metrics import FLOOR_CLEARANCE, GLIDE_LIFT, GLIDE_SPEED
from simdiff.text.base import EncoderCache

SCHEMA: str = "simdiff.model_check/1"
FLOOR_RULE: dict[str, float] = {"never_touch_clearance_m": FLOOR_CLEARANCE}
"""In the fingerprints of the sections whose counts depend on floor contact (a jump or a rise needs it since
session 51): parts stored before then are measured again."""
JUMPING_RULE: dict[str, int] = {"walk_run_jumping": 1}
"""In the speeds section's fingerprint: it counts the walk / run samples that jump since session 53."""
GLIDE_RULE: dict[str, float] = {"glide_speed_m_s": GLIDE_SPEED, "glide_lift_m": GLIDE_LIFT}
"""In the response sections' fingerprints: a gliding sample does not rise since session 52."""
RATIO_CI: dict[str, str] = {"size_ratio_ci95": "percentile bootstrap over samples"}
"""In the gravity sections' fingerprints: their size ratios carry a 95 % interval since session 52."""


def _stamp(path: str | Path, weights: str = "model.safetensors") -> dict[str, Any]:
    """A folder and the versions of its files (weights' size and mtime, ``config.json``'s hash): a stored part with
    another stamp is measured again."""
    p = Path(path).expanduser().resolve()
    out: dict[str, Any] = {"path": str(p)}
    f = p / weights
    if f.is_file():
        st = f.stat()
        out.update(size=st.st_size, mtime_ns=st.st_mtime_ns)
    config = p / "config.json"
    if config.is_file():  # settings such as mask_frames change samples without touching the weights
        out["config_sha256"] = hashlib.sha256(config.read_bytes()).hexdigest()
    return out


OTHER_EVALUATOR_KEYS: tuple[str, ...] = ("generated", "ground_truth", "ratios", "per_seed")
"""What a further evaluator's scoring of the same test-split motions keeps (the rest repeats the first's)."""


def _memoised(fn: Callable[[list[str], list[int], int], Any]) -> Callable[[list[str], list[int], int], Any]:
    """``fn`` with its outputs kept, so every evaluator scores the same motions and each is generated once.

    Holds every test-split motion of the run in memory: 4 bytes × 263 features per frame, e.g. 256 × 5 motions of
    ≤ 196 frames ≤ 0.27 GB."""
    store: dict[tuple[tuple[str, ...], tuple[int, ...], int], Any] = {}

    def generate(captions: list[str], lengths: list[int], seed: int) -> Any:
        key = (tuple(captions), tuple(int(n) for n in lengths), int(seed))
        if key not in store:
            store[key] = fn(captions, lengths, seed)
        return store[key]

    return generate


class ModelCheck:
    """Measures one model folder (:class:`CheckConfig`).

    Args:
        config: validated settings.
        text_encoder: factory ``name -> encoder`` replacing the models' own sentence encoders (tests).
        projector: replaces the simulator pool (tests); ``(motions, envs) -> iterable of (rollout, info)``.
        progress: tqdm bars; fresh: ignore stored parts.
    """

    def __init__(self, config: CheckConfig, *, text_encoder: Callable[[str], Any] | None = None, projector: Any = None,
                 progress: bool = True, fresh: bool = False, command: list[str] | None = None) -> None:
        self.config = config.validate()
        self.out = Path(config.out)
        self.progress = progress
        self.fresh = fresh
        self.command = command
        self._encoders = EncoderCache(self.config.device, text_encoder)
        self._injected = projector
        self._projector = projector
        self._generator: Any = None
        self._sets: dict[tuple[str, tuple[float, ...] | None], tuple[np.ndarray, np.ndarray]] = {}
        self.timings: dict[str, float] = {}

    # --- resources --------------------------------------------------------------------------
    def text_encoder(self, name: str) -> Any:
        return self._encoders(name)

    @property
    def generator(self) -> Any:
        if self._generator is None:
            from simdiff.model import MotionGenerator

            gen = MotionGenerator.load(self.config.model, self.config.device, load_text=False)
            gen.text_encoder = self.text_encoder(gen.config.text_encoder)
            self._generator = gen
        return self._generator

    @property
    def kind(self) -> str:
        """``backbone``, ``continuous`` or ``categorical`` (from config.json)."""
        try:
            sim = json.loads((Path(self.config.model) / "config.json").read_text(encoding="utf-8")).get("sim")
        except (json.JSONDecodeError, AttributeError, OSError) as exc:
            raise SimdiffError(f"{Path(self.config.model) / 'config.json'}: unreadable ({exc})") from None
        return "backbone" if sim is None else str(sim.get("mode", "continuous"))

    def env(self, phi: Sequence[float]) -> tuple[float, ...] | None:
        """φ as the generator takes it: None for a backbone (it takes no φ)."""
        return None if self.kind == "backbone" else tuple(float(v) for v in phi)

    @property
    def projector(self) -> Any:
        if self._projector is None:
            from simdiff.data.augment.projector import SimProjector

            r = self.config.response
            self._projector = SimProjector(None, r.workers, "process", r.residual_bound)
        return self._projector

    def close(self) -> None:
        """Stop the simulator workers this check started."""
        if self._projector is not None and self._injected is None:
            getattr(self._projector, "close", lambda: None)()
            self._projector = None

    # --- parts ------------------------------------------------------------------------------
    def base_inputs(self) -> dict[str, Any]:
        c = self.config
        lock = {"foot_lock": c.foot_lock, "foot_cleanup": CLEANUP_VERSION} if c.foot_lock else {}
        return {"schema": SCHEMA, "model": _stamp(c.model), "seeds": c.seeds, "steps": c.steps, "guidance": c.guidance,
                "alpha": c.alpha, "device": c.device, **lock, **({"anchor": c.anchor} if c.anchor != "adapters" else {}),
                **({"anchor_alpha": c.anchor_alpha} if c.anchor_alpha else {}),
                **({"anchor_t_max": c.anchor_t_max} if c.anchor_t_max is not None else {}),
                **({"edit_t": c.edit_t} if c.edit_t is not None else {}),
                **({"eta": c.eta} if c.eta else {}),
                **({"ballistic": c.ballistic} if c.ballistic else {})}

    def part(self, name: str, inputs: dict[str, Any], measure: Callable[[], dict[str, Any]]) -> dict[str, Any]:
        """The stored result of section ``name`` when its fingerprint matches, else measured and stored."""
        from simdiff.fsio import write_json

        inputs = {**self.base_inputs(), **inputs}
        fingerprint = hashlib.sha256(json.dumps(inputs, sort_keys=True, default=str).encode()).hexdigest()[:16]
        path = self.out / "parts" / f"{name}.json"
        if path.is_file() and not self.fresh:
            try:
                stored = json.loads(path.read_text(encoding="utf-8"))
            except json.JSONDecodeError:
                stored = {}
            if stored.get("fingerprint") == fingerprint:
                self.timings[name] = stored.get("wall_s", 0.0)
                return {**stored["result"], "cached": True}
        start = time.perf_counter()
        result = measure()
        wall = round(time.perf_counter() - start, 2)
        self.timings[name] = wall
        write_json(path, {"fingerprint": fingerprint, "inputs": inputs, "wall_s": wall, "result": result})
        return result

    def samples(self, name: str, batches: list[PromptBatch], phi: Sequence[float]) -> np.ndarray:
        """Joints of a prompt set under φ (memoised for this run)."""
        key = (name, self.env(phi))
        if key not in self._sets:
            c = self.config
            self._sets[key] = generate_set_flags(self.generator, batches, c.prompts.length, env=key[1], alpha=c.alpha,
                                                 steps=c.steps, guidance=c.guidance, progress=self.progress,
                                                 foot_lock=c.foot_lock, env_guidance=c.env_guidance, anchor=c.anchor,
                                                 env_guidance_fallback=c.env_guidance_fallback,
                                                 anchor_alpha=c.anchor_alpha, anchor_t_max=c.anchor_t_max,
                                                 ballistic=c.ballistic, edit_t=c.edit_t, eta=c.eta)
        return self._sets[key][0]

    def fell_back(self, name: str, phis: Sequence[Sequence[float]]) -> dict[str, Any]:
        """``{"fell_back": {"s_e": S, "samples": k, "of": n}}``: how many of the (already generated) samples of set
        ``name`` under ``phis`` were re-sampled at the fallback s_e; ``{}`` without a fallback."""
        s_e = self.config.env_guidance_fallback
        if s_e is None:
            return {}
        flags = [self._sets[(name, self.env(phi))][1] for phi in phis]
        return {"fell_back": {"s_e": s_e, "samples": int(sum(f.sum() for f in flags)),
                              "of": int(sum(len(f) for f in flags))}}

    # --- sections ---------------------------------------------------------------------------
    def test_split(self) -> dict[str, Any]:
        from simdiff.data.humanml3d import HumanML3D
        from simdiff.eval.evaluator import OurEvaluator, load_evaluator
        from simdiff.eval.model_check.split import measure_split
        from simdiff.eval.protocol import generator_fn

        c = self.config

        def score(path: str, dataset: Any, fn: Callable[..., Any]) -> dict[str, Any]:
            model = load_evaluator(path, c.device)
            evaluator = OurEvaluator(model, self.text_encoder(model.config.text_encoder))
            return measure_split(evaluator, dataset, fn, c.split, c.seeds, self.progress)

        def measure() -> dict[str, Any]:
            dataset = HumanML3D(c.corpus, c.split.split, seed=c.seeds[0])  # the protocol draws with its own rng
            env = self.env(EARTH)
            fn = generator_fn(self.generator, env=None if env is None else list(env), alpha=c.alpha, sampler="ddim",
                              steps=c.steps, guidance=c.guidance, foot_lock=c.foot_lock,
                              env_guidance=c.env_guidance, anchor=c.anchor, anchor_alpha=c.anchor_alpha,
                              anchor_t_max=c.anchor_t_max, ballistic=c.ballistic, edit_t=c.edit_t, eta=c.eta)
            if c.more_evaluators:
                fn = _memoised(fn)
            result = score(c.evaluator, dataset, fn)
            if c.more_evaluators:
                result["more_evaluators"] = [{"evaluator": _stamp(path)} | {k: v for k, v in score(path, dataset, fn).items()
                                                                           if k in OTHER_EVALUATOR_KEYS}
                                             for path in c.more_evaluators]
            return result

        key = {"corpus": _stamp(c.corpus, f"{c.split.split}.txt"), "evaluator": _stamp(c.evaluator), "split": c.split.__dict__}
        if c.more_evaluators:
            key["more_evaluators"] = [_stamp(path) for path in c.more_evaluators]
        return self.part("test_split", key, measure)

    def jump_batches(self) -> list[PromptBatch]:
        return plan_batches(JUMP_PROMPTS, self.config.prompts.jump_samples, self.config.seeds)

    def speed_batches(self) -> list[PromptBatch]:
        prompts = [p for ps in SPEED_PROMPTS.values() for p in ps]
        return plan_batches(prompts, self.config.prompts.speed_samples, self.config.seeds)

    def jumps(self) -> dict[str, Any]:
        from simdiff.eval.model_check.prompts import jump_summary

        batches = self.jump_batches()
        return self.part("jumps", {"prompts": JUMP_PROMPTS, "options": self.config.prompts.__dict__, **FLOOR_RULE},
                         lambda: jump_summary(self.samples("jumps", batches, EARTH), batches))

    def speeds(self) -> dict[str, Any]:
        from simdiff.eval.model_check.prompts import SPEED_REFERENCE, captioned_speeds, corpus_clips, speed_summary

        c = self.config

        def measure() -> dict[str, Any]:
            try:
                clips = corpus_clips(c.corpus, list(SPEED_PROMPTS), c.prompts.corpus_clips, c.seeds[0],
                                     c.prompts.length)
                captioned = captioned_speeds(c.corpus, SPEED_PROMPTS)
            except SimdiffError as exc:
                return {"skipped": str(exc)}
            batches = self.speed_batches()
            return speed_summary(self.samples("speeds", batches, EARTH), batches, SPEED_PROMPTS,
                                 {k: [v for v, _, _ in rows] for k, rows in clips.items()},
                                 {k: [j for _, j, _ in rows] for k, rows in clips.items()},
                                 {k: [n for _, _, n in rows] for k, rows in clips.items()}, captioned)

        return self.part("speeds", {"prompts": SPEED_PROMPTS, "options": c.prompts.__dict__, **JUMPING_RULE,
                                    **SPEED_REFERENCE,
                                    "corpus": _stamp(c.corpus, "manifest.json")}, measure)

    def response(self) -> dict[str, Any]:
        from simdiff.eval.model_check.response import gravity_response, wind_response

        c = self.config
        if self.kind != "continuous":
            return {"skipped": f"the model is a {self.kind} model without a continuous Sim Encoder: no φ to respond to"}
        if not c.response.enabled:
            return {"skipped": "turned off (--no-response)"}
        inputs = {"options": c.response.__dict__, "prompts": c.prompts.__dict__, "injected": self._injected is not None,
                  **FLOOR_RULE, **GLIDE_RULE,
                  # the only sections off Earth: environment guidance leaves the Earth sections' motions as they are
                  **({"env_guidance": c.env_guidance} if c.env_guidance != 1.0 else {}),
                  **({"env_guidance_fallback": c.env_guidance_fallback, "fallbacks_counted": 1}
                     if c.env_guidance_fallback is not None else {})}
        jumps = self.jump_batches()
        moon = (MOON_G, 0.0, 0.0)
        grav = self.part("gravity", {**inputs, **RATIO_CI, "g": MOON_G, "jump_prompts": JUMP_PROMPTS},
                         lambda: {**gravity_response(units(jumps), self.samples("jumps", jumps, EARTH),
                                                     self.samples("jumps", jumps, moon), MOON_G, self.projector,
                                                     resamples=c.response.resamples, seed=c.seeds[0]),
                                  **self.fell_back("jumps", [moon])})
        runs = [b for b in self.speed_batches() if b.prompt in SPEED_PROMPTS["run"]]  # session 50's floating runs
        grav_runs = self.part("gravity_runs", {**inputs, **RATIO_CI, "g": MOON_G, "run_prompts": SPEED_PROMPTS["run"]},
                              lambda: {**gravity_response(units(runs), self.samples("runs", runs, EARTH),
                                                          self.samples("runs", runs, moon), MOON_G,
                                                          self.projector, resamples=c.response.resamples,
                                                          seed=c.seeds[0]), **self.fell_back("runs", [moon])})
        walk = [b for b in self.speed_batches() if b.prompt in SPEED_PROMPTS["walk"]]
        winds = [(EARTH[0], WIND_N, 0.0), (EARTH[0], -WIND_N, 0.0), (EARTH[0], 0.0, WIND_N), (EARTH[0], 0.0, -WIND_N)]
        wind = self.part("wind", {**inputs, "wind": winds, "walk_prompts": SPEED_PROMPTS["walk"]},
                         lambda: {**wind_response(units(walk), self.samples("walks", walk, EARTH),
                                                  {w: self.samples("walks", walk, w) for w in winds}, self.projector,
                                                  resamples=c.response.resamples, seed=c.seeds[0]),
                                  **self.fell_back("walks", winds)})
        return {"gravity": grav, "gravity_runs": grav_runs, "wind": wind, "simulator": "the projector's flight clock (flights follow gravity)"
                if self._injected is None else "injected projector (tests)"}

    # --- all --------------------------------------------------------------------------------
    def run(self, generation_speed: dict[str, Any] | None = None) -> dict[str, Any]:
        """Measure every section, write ``check.json`` and ``check.md``; returns the report."""
        from simdiff.eval.experiments.provenance import now, provenance
        from simdiff.eval.model_check.report import markdown
        from simdiff.eval.model_check.verdict import figures, verdicts
        from simdiff.fsio import check_writable, write_json, write_text

        c = self.config
        check_writable(self.out / "check.json")
        kind = self.kind
        if kind == "categorical":
            raise SimdiffError(f"{c.model}: a categorical SimDiff model; the check needs a backbone or a continuous one")
        if c.env_guidance != 1.0 and kind != "continuous":
            raise SimdiffError(f"{c.model}: --env-guidance needs a SimDiff model with a continuous Sim Encoder; "
                               f"this is a {kind} model (leave it at 1)")
        if c.env_guidance_fallback is not None and kind != "continuous":
            raise SimdiffError(f"{c.model}: --env-guidance-fallback needs a SimDiff model with a continuous Sim Encoder; "
                               f"this is a {kind} model (leave it out)")
        if c.anchor != "adapters" and kind != "continuous":
            raise SimdiffError(f"{c.model}: --anchor {c.anchor} needs a SimDiff model with a continuous Sim Encoder; "
                               f"this is a {kind} model (leave it at adapters)")
        report: dict[str, Any] = {"schema": SCHEMA, "model": {**_stamp(c.model), "kind": kind},
                                  "corpus": str(Path(c.corpus).resolve()), "evaluator": _stamp(c.evaluator),
                                  "settings": {**c.as_dict(), **({"foot_cleanup": CLEANUP_VERSION} if c.foot_lock else {})},
                                  "provenance": provenance(c.seeds[0], c.device, self.command)}
        start = time.perf_counter()
        try:
            report["test_split"] = self.test_split()
            report["jumps"] = self.jumps()
            report["speeds"] = self.speeds()
            report["response"] = self.response()
        finally:
            self.close()
        report["generation_speed"] = generation_speed or {"skipped": "run with --speed to measure it"}
        report["figures"] = figures(report)
        report["verdicts"] = verdicts(report["figures"])
        report["timings_s"] = {**self.timings, "total": round(time.perf_counter() - start, 2)}
        report["finished"] = now()
        write_json(self.out / "check.json", report)
        write_text(self.out / "check.md", markdown(report))
        return report
