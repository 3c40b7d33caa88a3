"""The machinery every experiment shares: resources, generation, row cache, estimates.

An experiment is a list of :class:`RowPlan` (what to measure, how long it should take,
everything that determines the result). :class:`Runner` turns each plan into a row:

* cached: ``rows/<key>.json`` exists with the same *fingerprint* (a hash of the plan's
  inputs: model folder and file stamp, sampler, α, φ, protocol, corpus, evaluator, seed);
  a row whose inputs changed is measured again;
* reused: an identical row (same fingerprint) in one of ``reuse_rows_from`` reports is copied
  (table1 takes its SimDiff DDIM rows from table2 when the protocols match);
* measured, then written atomically, so an interrupted run resumes after the last finished row.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import os
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

import numpy as np
import torch

from simdiff.diffusion.config import SamplingConfig
from simdiff.motion.features import features_to_joints
from simdiff.motion.metrics import physics_metrics
from simdiff.motion.rigid import batch_joints_from_features, decode_inputs
from simdiff.errors import SimdiffError
from simdiff.eval.experiments.config import ExperimentConfig, ModelSpec
from simdiff.eval.experiments.provenance import folder_stamp, provenance
from simdiff.eval.protocol import GenerateFn, ProtocolConfig, evaluate_t2m, finish_summary, generator_fn
from simdiff.text.base import EncoderCache

EARTH: tuple[float, float, float] = (-9.81, 0.0, 0.0)
CAPTION_SETS: tuple[str, ...] = ("all", "unseen")
FPS: float = 20.0


@dataclass
class RowPlan:
    """One row to measure.

    Attributes:
        key: file name in ``rows/`` (readable, unique within the experiment).
        meta: labels copied into the row (method, sampler, α, φ, ...).
        inputs: everything that determines the measurement (hashed into the fingerprint).
        estimate_s: expected seconds from the config's cost model.
        measure: ``runner -> measurements`` (a JSON-able dict).
    """

    key: str
    meta: dict[str, Any]
    inputs: dict[str, Any]
    estimate_s: float
    measure: Callable[["Runner"], dict[str, Any]]

    @property
    def fingerprint(self) -> str:
        text = json.dumps(self.inputs, sort_keys=True, default=str)
        return hashlib.sha256(text.encode("utf-8")).hexdigest()[:16]


def env_key(env: Any) -> str:
    """``g-9.81_wx0_wy0`` for φ (file-name safe)."""
    g, wx, wy = (float(v) for v in env)
    return f"g{g:g}_wx{wx:g}_wy{wy:g}"


def safe(text: str) -> str:
    """A label as a file-name fragment."""
    return "".join(c if c.isalnum() or c in "-._" else "_" for c in text).strip("_") or "row"


class Runner:
    """Loads models/evaluator/corpus once and measures an experiment's rows into ``<out_dir>/<name>/``."""

    def __init__(self, config: ExperimentConfig, *, projector: Any = None, command: list[str] | None = None,
                 progress: bool = True, text_encoder: Callable[[str], Any] | None = None) -> None:
        """``projector`` and ``text_encoder`` (a factory: encoder name → encoder) replace the simulator
        and the models' own text encoders (tests); neither enters the rows' fingerprints."""
        self.config = config
        self.out = Path(config.out_dir) / config.name
        self.rows_dir = self.out / "rows"
        self.progress = progress
        self.provenance = provenance(config.seed, config.device, command)
        if config.threads:
            self.provenance["machine"]["torch_threads"] = config.threads
        self._injected = projector
        self._projector: Any = projector
        self._finish_projector: Any = None
        self._models: dict[str, Any] = {}
        self._encoders = EncoderCache(self.config.device, text_encoder)
        self._evaluator: Any = None
        self._datasets: dict[str, Any] = {}
        self.captions = "all"
        """The caption set protocol rows draw (:data:`CAPTION_SETS`); an experiment sets it around a row."""
        self._lengths: np.ndarray | None = None
        self.notes: dict[str, Any] = {}
        """Facts an experiment fixes while planning and reports when finishing (table1: the best α used)."""

    # --- resources ------------------------------------------------------------------------
    def text_encoder(self, name: str) -> Any:
        """The sentence encoder ``name`` (one instance per run), or the injected stand-in's."""
        return self._encoders(name)

    def model(self, spec: ModelSpec) -> Any:
        """The :class:`simdiff.model.MotionGenerator` of ``spec`` (loaded once per folder and role).

        A ``backbone`` role (MDM, PhysDiff) whose folder holds a SimDiff model gets that model's frozen
        backbone alone (φ-blind, as ``simdiff train export-backbone`` writes it), never its adapters.
        """
        path = self.config.model_path(spec)
        strip = self.backbone_of_simdiff(spec)
        key = str(path) + ("#backbone" if strip else "")
        if key not in self._models:
            from simdiff.inference.generator import MotionGenerator

            if not (path / "model.safetensors").is_file():
                hint = f" (set it with --{spec.model.replace('_', '-')} DIR)" if spec.model and not spec.path else ""
                raise SimdiffError(f"model folder {path} of {spec.name!r} has no model.safetensors{hint}")
            gen = MotionGenerator.load(path, self.config.device, load_text=False)
            if strip:
                gen = MotionGenerator(gen.network.backbone, dataclasses.replace(gen.config, sim=None), None,
                                      gen.mean, gen.std, self.config.device)
            gen.text_encoder = self.text_encoder(gen.config.text_encoder)
            self._models[key] = gen
        return self._models[key]

    def folder_sim_mode(self, spec: ModelSpec) -> str | None:
        """``continuous``, ``categorical`` or None (backbone) from the folder's config.json (by role without one)."""
        path = self.config.model_path(spec) / "config.json"
        if path.is_file():
            try:
                sim = json.loads(path.read_text(encoding="utf-8")).get("sim")
                return None if sim is None else str(sim.get("mode", "continuous"))
            except (json.JSONDecodeError, AttributeError):
                pass
        return {"adapters": "continuous", "adapters_binary": "categorical"}.get(spec.model)

    def backbone_of_simdiff(self, spec: ModelSpec) -> bool:
        """True when a ``backbone`` role points at a SimDiff model folder (its backbone alone is used)."""
        return spec.model == "backbone" and self.folder_sim_mode(spec) is not None

    def sim_mode(self, spec: ModelSpec) -> str | None:
        """How ``spec`` generates: ``continuous``, ``categorical`` or None (φ-blind backbone: always for the
        ``backbone`` role, whatever its folder holds)."""
        return None if spec.model == "backbone" else self.folder_sim_mode(spec)

    def is_simdiff(self, spec: ModelSpec) -> bool:
        return self.sim_mode(spec) is not None

    @property
    def evaluator(self) -> Any:
        if self._evaluator is None:
            spec = self.config.evaluator
            if spec.kind == "ours":
                from simdiff.eval.evaluator import OurEvaluator, load_evaluator

                if not spec.path:
                    raise SimdiffError("no evaluator folder given (set evaluator.path or --evaluator DIR)")
                model = load_evaluator(Path(spec.path).expanduser(), self.config.device)
                self._evaluator = OurEvaluator(model, self.text_encoder(model.config.text_encoder))
            elif spec.kind == "t2m":
                from simdiff.eval.t2m_official import OfficialT2MEvaluator

                if not spec.glove or not spec.meta:
                    raise SimdiffError("the t2m evaluator needs 'glove' and 'meta' folders in the config")
                self._evaluator = OfficialT2MEvaluator.from_files(spec.path, spec.glove, spec.meta, self.config.device)
            else:
                raise SimdiffError(f"unknown evaluator kind {spec.kind!r}; choose ours or t2m")
        return self._evaluator

    @property
    def dataset(self) -> Any:
        """The split's items; with :attr:`captions` ``unseen``, only captions no train item has (normalised)."""
        if self.captions not in self._datasets:
            from simdiff.data.humanml3d import HumanML3D

            corpus = Path(self.config.corpus).expanduser()
            if not corpus.is_dir():
                raise SimdiffError(f"corpus folder {corpus} not found (set it with --corpus DIR)")
            unseen = "train" if self.captions == "unseen" else None
            self._datasets[self.captions] = HumanML3D(corpus, self.config.split, seed=self.config.seed, unseen_in=unseen)
        return self._datasets[self.captions]

    def _pool_projector(self, anchor_stance: bool) -> Any:
        """A persistent simulator pool with the config's parallelism and residual bound."""
        from simdiff.data.augment.projector import SimProjector

        p = self.config.projector
        corpus = Path(self.config.corpus).expanduser()
        stats = str(corpus) if (corpus / "Mean.npy").is_file() else None  # d_L2 needs them; tracking does not
        return SimProjector(stats, p.workers, p.backend, p.residual_bound, anchor_stance=anchor_stance)

    @property
    def sim(self) -> Any:
        """The projector PhysDiff and re-tracking use (injected, or a persistent simulator pool)."""
        if self._projector is None:
            self._projector = self._pool_projector(anchor_stance=False)
        return self._projector

    @property
    def finish_sim(self) -> Any:
        """The projector of the simulated finish: :attr:`sim`'s tracker with the planted feet anchored
        (``simdiff generate --simulate``'s setting, :func:`simdiff.product.simulate.simulate_finish`)."""
        if self._injected is not None:
            return self._injected
        if self._finish_projector is None:
            self._finish_projector = self._pool_projector(anchor_stance=True)
        return self._finish_projector

    def serial_projector(self, anchor_stance: bool = False) -> Any:
        """An in-process simulator (batch-1 timing), or the injected projector."""
        if self._injected is not None:
            return self._injected
        from simdiff.data.augment.projector import SimProjector

        return SimProjector(None, 1, "serial", self.config.projector.residual_bound, anchor_stance=anchor_stance)

    def close(self) -> None:
        """Stop the simulator workers this runner started."""
        if self._injected is None:
            for p in (self._projector, self._finish_projector):
                if p is not None:
                    getattr(p, "close", lambda: None)()
            self._projector = self._finish_projector = None

    def preflight(self, needs_evaluator: bool, needs_corpus: bool = True) -> None:
        """Check that the corpus, the evaluator and every model folder exist before measuring anything."""
        c = self.config
        corpus = Path(c.corpus).expanduser()
        if needs_corpus and not (corpus / f"{c.split}.txt").is_file():
            raise SimdiffError(f"corpus {corpus} has no {c.split}.txt (set the corpus with --corpus DIR)")
        if needs_evaluator and c.evaluator.kind == "ours" and not (Path(c.evaluator.path).expanduser() / "model.safetensors").is_file():
            raise SimdiffError(f"evaluator folder {c.evaluator.path or '(none)'} has no model.safetensors "
                               "(set it with --evaluator DIR)")
        for spec in c.models:
            path = c.model_path(spec)
            if not (path / "model.safetensors").is_file():
                hint = f" (set it with --{spec.model.replace('_', '-')} DIR)" if spec.model and not spec.path else ""
                raise SimdiffError(f"model folder {path} of {spec.name!r} has no model.safetensors{hint}")

    # --- what determines a row ------------------------------------------------------------
    def data_inputs(self) -> dict[str, Any]:
        """Corpus, split, evaluator, seed and text encoder (part of every protocol row's fingerprint)."""
        e = self.config.evaluator
        return {"corpus": str(Path(self.config.corpus).expanduser().resolve()), "split": self.config.split,
                "evaluator": {**dataclasses.asdict(e), "path": folder_stamp(e.path)}, "seed": self.config.seed,
                "text_encoder": self.config.text_encoder}

    def method_inputs(self, spec: ModelSpec, sampler: str, alpha: float | None, env: Any = None) -> dict[str, Any]:
        """Model file, sampler, α, φ and PhysDiff settings of one method row."""
        out: dict[str, Any] = {"model": folder_stamp(str(self.config.model_path(spec))),
                               "sampling": self.sampling(spec, sampler, alpha).to_dict(),
                               "env": None if env is None else [float(v) for v in env],
                               "env_index": spec.env_index, "device": self.config.device}
        if self.backbone_of_simdiff(spec):
            out["backbone_only"] = True  # the folder's SimDiff model, adapters left out
        out.update(decode_inputs(out["sampling"]["foot_lock"]))  # measured on the written joints
        if spec.physdiff is not None:
            out["physdiff"] = dataclasses.asdict(self.physdiff_config(spec, sampler, env))
            out["projector"] = dataclasses.asdict(self.config.projector)
        if spec.simulate:
            from simdiff.sim.retarget.contacts import ANCHOR_VERSION

            out["simulate"] = True
            out["anchor_version"] = ANCHOR_VERSION  # the finish anchors planted feet; a rule change re-measures
            out["projector"] = dataclasses.asdict(self.config.projector)
        return out

    # --- generation -------------------------------------------------------------------------
    def physdiff_config(self, spec: ModelSpec, sampler: str, env: Any = None) -> Any:
        """The :class:`PhysDiffConfig` of a PhysDiff row (sampler, steps, φ, guidance filled in)."""
        from simdiff.baselines.physdiff import PhysDiffConfig
        from simdiff.model.config import config_from_dict

        base = {k: v for k, v in (spec.physdiff or {}).items() if k not in ("sampler", "steps", "env", "guidance")}
        cfg = config_from_dict(base, PhysDiffConfig)
        sampling = self.sampling(spec, sampler)
        cfg.sampler, cfg.steps, cfg.guidance = sampler, sampling.steps, sampling.guidance
        cfg.env = tuple(float(v) for v in (env if env is not None else spec.env or EARTH))
        cfg.residual_bound = self.config.projector.residual_bound
        cfg.project_at = tuple(int(t) for t in cfg.project_at)
        return cfg

    def generate_fn(self, spec: ModelSpec, sampler: str, alpha: float | None = None, env: Any = None) -> GenerateFn:
        """``(captions, lengths, seed) -> (B, T, 263)`` raw features for one method row."""
        if spec.env_guidance not in (None, 1.0) and self.sim_mode(spec) != "continuous":
            raise SimdiffError(f"model {spec.name!r}: env_guidance {spec.env_guidance:g} needs continuous SimDiff "
                               "adapters (φ does not reach this method)")
        gen = self.model(spec)
        phys = self.physdiff_config(spec, sampler, env) if spec.physdiff is not None else None
        use_env = None
        if gen.is_simdiff and gen.config.sim.mode == "continuous":
            use_env = list(env) if env is not None else spec.env
        return generator_fn(gen, self.sampling(spec, sampler, alpha), env=use_env,
                            env_index=spec.env_index if gen.is_simdiff else None, physdiff=phys,
                            projector=self.sim if phys is not None else None, simulate=spec.simulate,
                            finish_projector=self.finish_sim if spec.simulate else None)

    def sampling(self, spec: ModelSpec, sampler: str, alpha: float | None = None) -> SamplingConfig:
        """The model folder's ``sampling.json`` with the row's sampler, α and the method's overrides."""
        from simdiff.inference.default import sampling_config
        continuous = self.sim_mode(spec) == "continuous"
        env_guidance = spec.env_guidance if continuous else 1.0  # φ-blind: no φ to push
        flight_passes = spec.flight_passes if continuous else 0  # φ-blind methods are sampled without SimDiff's guidance
        eta = 0.0 if spec.physdiff is not None else None  # PhysDiff's projection sampler is deterministic DDIM
        return sampling_config(self.config.model_path(spec)).updated(
            sampler=sampler, steps=spec.sampler_steps(sampler), guidance=spec.guidance,
            guidance_min_t=spec.guidance_min_t, eta=eta,
            env_guidance=env_guidance, flight_passes=flight_passes, alpha=spec.alpha if alpha is None else float(alpha))

    def alpha(self, spec: ModelSpec) -> float:  # the α of a method where the experiment does not sweep it
        return self.sampling(spec, "ddim").alpha

    def generate(self, fn: GenerateFn, captions: list[str], lengths: list[int], seed: int) -> tuple[torch.Tensor, float]:
        """Generate in batches of the protocol's size; returns ((N, T, 263) features, seconds)."""
        bs = self.config.protocol.batch_size
        out, seconds = [], 0.0
        for k in range(0, len(captions), bs):
            start = time.perf_counter()
            feats = fn(captions[k : k + bs], lengths[k : k + bs], seed + k)
            seconds += time.perf_counter() - start
            out.append(feats)
        frames = max(f.shape[1] for f in out)
        return torch.cat([torch.nn.functional.pad(f, (0, 0, 0, frames - f.shape[1])) for f in out]), seconds

    def test_motions(self, n: int) -> dict[str, Any]:
        """``n`` test items drawn as the protocol draws them (seeded): captions, lengths, raw GT features."""
        ds = self.dataset
        rng = np.random.default_rng([self.config.seed, 99])
        order = np.concatenate([rng.permutation(len(ds)) for _ in range(n // len(ds) + 1)])[:n]
        items = [ds.get(int(i), rng) for i in order]
        raw = [ds.normalizer.denormalize(it["motion"][: it["length"]]) for it in items]
        return {"captions": [it["caption"] for it in items], "lengths": [int(it["length"]) for it in items],
                "features": raw, "ids": [it["id"] for it in items]}

    # --- measurements ---------------------------------------------------------------------
    def protocol_measure(self, spec: ModelSpec, sampler: str, alpha: float | None, env: Any = None,
                         protocol: ProtocolConfig | None = None) -> dict[str, Any]:
        """The T2M protocol + physics metrics of one method row."""
        proto = protocol or self.config.protocol
        fn = self.generate_fn(spec, sampler, alpha, env)
        result = evaluate_t2m(self.evaluator, self.dataset, fn, proto, self.progress)
        reps = result["replications"]
        out = {"summary": result["summary"]["generated"], "replications": [r["generated"] for r in reps],
               "s_per_motion": float(np.mean([r["gen_s_per_sample"] for r in reps])),
               "samples_per_replication": result["samples_per_replication"], "replications_run": len(reps),
               "split_size": result["split_size"], "seeds": proto.seeds_used()}
        if spec.simulate and getattr(fn, "finish_log", None):
            out["finish"] = finish_summary(fn.finish_log)
        return out

    def gt_measure(self) -> dict[str, Any]:
        """The ground-truth row of the protocol."""
        result = evaluate_t2m(self.evaluator, self.dataset, None, self.config.protocol, self.progress)
        return {"summary": result["summary"]["ground_truth"], "samples_per_replication": result["samples_per_replication"],
                "replications_run": len(result["replications"]), "split_size": result["split_size"],
                "seeds": self.config.protocol.seeds_used()}

    def subset_measure(self, spec: ModelSpec, sampler: str, alpha: float | None, n: int, env: Any = None) -> dict[str, Any]:
        """Physics metrics and time of ``n`` generated test motions (too few for the T2M metrics)."""
        items = self.test_motions(n)
        fn = self.generate_fn(spec, sampler, alpha, env)
        feats, seconds = self.generate(fn, items["captions"], items["lengths"], self.config.seed * 1_000_003)
        lengths = np.clip(np.asarray(items["lengths"]), 2, feats.shape[1])
        joints = batch_joints_from_features(feats, lengths, fn.foot_lock)
        physics = physics_metrics(joints, lengths)
        gt = [np.asarray(features_to_joints(torch.as_tensor(f).double())) for f in items["features"]]
        gt_float = float(np.average([physics_metrics(j)["floating"] for j in gt], weights=[len(j) for j in gt]))
        physics["floating_to_gt"] = abs(physics["floating"] - gt_float)
        physics["phys_err"] = physics["penetration"] + physics["sliding"] + physics["floating_to_gt"]
        seeds = {"data": [self.config.seed, 99], "generation": self.config.seed * 1_000_003}
        return {"physics": physics, "gt_floating": gt_float, "s_per_motion": seconds / n, "samples": n, "seeds": seeds}

    def ddpm_protocol(self) -> ProtocolConfig | None:
        """Protocol of DDPM rows under ``ddpm_samples`` (None: physics-only subset rows)."""
        c, proto = self.config, self.config.protocol
        if c.ddpm_samples == 0:
            return proto
        if c.ddpm_samples < proto.batch_size:
            return None
        batches = c.ddpm_samples // proto.batch_size
        return dataclasses.replace(proto, replications=c.ddpm_replications, samples_limit=(batches - 1) * proto.batch_size,
                                   mm_prompts=0)

    # --- estimates --------------------------------------------------------------------------
    def test_lengths(self) -> np.ndarray | None:
        """Frames of each test clip (read without loading the dataset), or None without a corpus."""
        if self._lengths is None:
            root = Path(self.config.corpus).expanduser()
            split = root / f"{self.config.split}.txt"
            if not split.is_file():
                return None
            names = [s.strip() for s in split.read_text(encoding="utf-8").splitlines() if s.strip()]
            lengths = []
            for name in names:
                f = root / "new_joint_vecs" / f"{name}.npy"
                if f.is_file():
                    lengths.append(np.load(f, mmap_mode="r").shape[0])
            self._lengths = np.asarray(lengths)
        return self._lengths if len(self._lengths) else None

    def mean_motion_s(self) -> float:
        lengths = self.test_lengths()
        return float(np.minimum(lengths, 196).mean() / FPS) if lengths is not None else self.config.costs.mean_motion_s

    def samples_per_replication(self, proto: ProtocolConfig) -> int:
        lengths = self.test_lengths()
        n_test = len(lengths) if lengths is not None else 10**9
        return min(proto.max_batches, n_test // proto.batch_size) * proto.batch_size

    def motion_seconds(self, spec: ModelSpec, sampler: str, n: int, motion_s: float | None = None,
                       workers: int | None = None) -> float:
        """Estimated seconds to generate ``n`` motions (with PhysDiff's projections)."""
        c = self.config.costs
        s = n * (c.ddpm_s_per_motion if sampler == "ddpm" else c.ddim_s_per_motion)
        if sampler == "ddpm" and spec.ddpm_steps:
            s *= spec.ddpm_steps / 1000
        if sampler == "ddim" and spec.steps:
            s *= spec.steps / 50
        if spec.physdiff is not None:
            calls = len(self.physdiff_config(spec, sampler).project_at)
            s += n * calls * self.projection_seconds(motion_s, workers)
        if spec.simulate:
            s += n * self.projection_seconds(motion_s, workers)
        return s

    def projection_seconds(self, motion_s: float | None = None, workers: int | None = None) -> float:
        """Estimated wall seconds of one projection (per motion, with the pool's parallelism)."""
        p = self.config.projector
        if workers is None:
            workers = 1 if p.backend == "serial" else (p.workers or os.cpu_count() or 1)
        motion_s = self.mean_motion_s() if motion_s is None else motion_s
        return self.config.costs.projection_cpu_s_per_motion_s * motion_s / max(1, workers)

    def protocol_seconds(self, spec: ModelSpec | None, sampler: str, proto: ProtocolConfig) -> float:
        n = self.samples_per_replication(proto)
        mm = proto.mm_prompts * proto.mm_repeats if proto.mm_prompts > 0 else 0
        evals = proto.replications * (2 * n + n + mm) * self.config.costs.eval_s_per_motion
        if spec is None:
            return evals
        return evals + proto.replications * self.motion_seconds(spec, sampler, n + mm)

    # --- rows -------------------------------------------------------------------------------
    def status(self, plan: RowPlan) -> tuple[str, dict[str, Any] | None]:
        """(``cached`` | ``reuse`` | ``measure``, the stored row if any)."""
        path = self.rows_dir / f"{plan.key}.json"
        if path.is_file():
            row = json.loads(path.read_text(encoding="utf-8"))
            if row.get("fingerprint") == plan.fingerprint:
                return "cached", row
        for other in self.config.reuse_rows_from:
            folder = Path(self.config.out_dir) / other / "rows"
            for candidate in sorted(folder.glob("*.json")) if folder.is_dir() else []:
                row = json.loads(candidate.read_text(encoding="utf-8"))
                if row.get("fingerprint") == plan.fingerprint:
                    return "reuse", {**row, "reused_from": str(candidate)}
        return "measure", None

    def fetch(self, plan: RowPlan) -> dict[str, Any]:
        """The row of ``plan``: cached, reused or measured (and stored)."""
        from simdiff.model.checkpoint import atomic_write_json

        state, row = self.status(plan)
        if state == "cached" and row is not None:
            return row
        if state == "reuse" and row is not None:
            measured = {k: v for k, v in row.items() if k not in plan.meta and k != "key"}
            value = {"key": plan.key, **plan.meta, **measured}
        else:
            start = time.perf_counter()
            measured = plan.measure(self)
            value = {"key": plan.key, **plan.meta, **measured, "fingerprint": plan.fingerprint,
                     "estimate_s": round(plan.estimate_s, 1), "wall_s": round(time.perf_counter() - start, 2)}
        atomic_write_json(value, self.rows_dir / f"{plan.key}.json")
        return value

    def execute(self, plans: list[RowPlan]) -> list[dict[str, Any]]:
        """Fetch every row, with a progress bar over rows."""
        from tqdm import tqdm

        keys = [p.key for p in plans]
        dup = {k for k in keys if keys.count(k) > 1}
        if dup:
            raise SimdiffError(f"two rows share the key {sorted(dup)[0]!r}; give the models distinct names")
        rows = []
        bar = tqdm(plans, desc=self.config.name, unit="row", disable=not self.progress, dynamic_ncols=True)
        for plan in bar:
            bar.set_postfix_str(f"{plan.key} (~{plan.estimate_s / 60:.1f} min)")
            rows.append(self.fetch(plan))
        return rows
