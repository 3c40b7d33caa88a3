"""Experiment configs (``configs/eval_*.json``): what to measure, where the models are, CPU budgets.

A config is JSON. Model folders are named once, by role, in ``paths`` (relative paths are
resolved against the working directory when the experiment runs) and model rows refer to
a role (``"model": "backbone"``); ``corpus`` and ``evaluator.path`` likewise. Everything can
be overridden from the command line with dotted keys (``protocol.replications=3``,
``paths.backbone=/tmp/bb/model``, ``models.0.alpha=0.5``), and a named *budget*
(``budgets.quick``) is a stored set of such overrides with a sentence saying what it means.
Order of application: the file, then the budget, then the command-line overrides.
"""

from __future__ import annotations

import copy
import json
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from simdiff.errors import SimdiffError
from simdiff.eval.protocol import ProtocolConfig

KINDS: tuple[str, ...] = ("table1", "table2", "fig4", "fig5", "retrack", "env_response", "contacts", "editing",
                          "following", "heldout")
"""Experiment kinds: the paper's tables and figures, then the project's own reports."""
ROLES: tuple[str, ...] = ("backbone", "adapters", "adapters_binary")
"""Model roles ``paths`` may name: MDM backbone, continuous (φ) adapters, categorical (binary) adapters."""
SAMPLERS: tuple[str, ...] = ("ddpm", "ddim")


@dataclass
class ModelSpec:
    """One method of an experiment.

    Attributes:
        name: label in tables and figures (``MDM``, ``PhysDiff``, ``SimDiff``).
        model: role in :attr:`ExperimentConfig.paths` (or give ``path``).
        path: explicit model folder (model.safetensors + config.json); overrides ``model``.
        env: φ = (g_z m/s², w_x N, w_y N) for continuous SimDiff models (None: Earth).
        env_index: category for categorical SimDiff models (binary setting: 1 = simulated).
        alpha: adapter strength where the experiment does not sweep it (None: the model's ``sampling.json``).
        steps: DDIM steps; ddpm_steps: DDPM steps (None: the model's, else 50 and 1000).
        guidance: classifier-free guidance scale (None: the model's ``sampling.json``).
        guidance_min_t: the lowest timestep guided by the text (None: the model's ``sampling.json``; 0 with
            ``steps`` 50: the 50-step path).
        env_guidance: environment guidance s_e of continuous SimDiff models (None: the model's ``sampling.json``;
            :mod:`simdiff.diffusion.guidance`).
        flight_passes: flight guidance of continuous SimDiff models (None: the model's ``sampling.json``; 0: off;
            :mod:`simdiff.inference.flight_guidance`); φ-blind methods sample without it. Every other sampling
            setting (η, ``edit_t``, foot cleanup) is the model's, so a row samples as ``simdiff generate`` does.
        physdiff: :class:`simdiff.baselines.physdiff.PhysDiffConfig` fields → PhysDiff sampling
            (the row's sampler, steps and φ are filled in by the experiment).
        simulate: simulated finish: each final sample is re-tracked under its φ (Earth for
            categorical models) and the simulator's motion replaces it where tracked
            (``simdiff generate --simulate``); rows named e.g. ``SimDiff + simulated finish``.
        alphas: this method's own α list in a table that lists α (table1: numbers and
            ``"best"``), instead of the table's ``alphas`` (None: the table's); e.g. the simulated
            finish at the shipped α only, where a best-α row of it would double the CPU time.
        samplers: this method's own samplers, a subset of the table's ``samplers`` (None: the
            table's); e.g. DDPM rows for MDM, PhysDiff and SimDiff only, where every method's
            DDPM row would cost a CPU hour more.
        compare_to: the name of a method this one is compared with, row by row (same captions and seeds): the
            report gives their paired differences (e.g. the shipped sampling against the 50-step path).
    """

    name: str
    model: str = ""
    path: str = ""
    env: list[float] | None = None
    env_index: int | None = None
    alpha: float | None = None
    steps: int | None = None
    ddpm_steps: int | None = None
    guidance: float | None = None
    guidance_min_t: int | None = None
    env_guidance: float | None = None
    flight_passes: int | None = None
    physdiff: dict[str, Any] | None = None
    simulate: bool = False
    alphas: list[float | str] | None = None
    samplers: list[str] | None = None
    compare_to: str | None = None

    def sampler_steps(self, sampler: str) -> int | None:
        """Steps of ``sampler`` for this method."""
        return self.ddpm_steps if sampler == "ddpm" else self.steps

    def own_samplers(self, table: list[str]) -> list[str]:
        """The samplers this method runs in a table that lists ``table`` (the table's order)."""
        return [s for s in table if self.samplers is None or s in self.samplers]


@dataclass
class EvaluatorSpec:
    """Which evaluator: ``ours`` (``path``) or ``t2m`` (``path`` = finest.tar, ``glove``, ``meta`` folders)."""

    kind: str = "ours"
    path: str = ""
    glove: str | None = None
    meta: str | None = None


@dataclass
class ProjectorSpec:
    """The simulator that PhysDiff and re-tracking use.

    Attributes:
        workers: projection processes (0: all cores); backend: ``process`` or ``serial``.
        residual_bound: tracker root-residual bound (fraction of m·|g_z|; 0 = strict).
    """

    workers: int = 0
    backend: str = "process"
    residual_bound: float = 0.5


@dataclass
class CostModel:
    """Seconds used to estimate rows before running them (``--dry-run`` and every report).

    Defaults: the small model on this project's 2-core CPU machine, batch 1.

    Attributes:
        ddim_s_per_motion: DDIM-50 generation.
        ddpm_s_per_motion: DDPM-1000 generation.
        projection_cpu_s_per_motion_s: one simulator projection, CPU seconds per second of motion.
        mean_motion_s: mean test motion length (s) when the corpus cannot be read.
        eval_s_per_motion: evaluator embedding and metrics.
    """

    ddim_s_per_motion: float = 0.9
    ddpm_s_per_motion: float = 17.7
    projection_cpu_s_per_motion_s: float = 0.2
    mean_motion_s: float = 6.7
    eval_s_per_motion: float = 0.01


@dataclass
class TimingOptions:
    """Figure 4: inference time per motion at batch 1.

    Attributes:
        text, length: the prompt and its frames (196 = MDM's fixed 9.8 s).
        repeats, ddpm_repeats: timed runs per DDIM / DDPM cell (the median is reported).
        warmup: untimed DDIM runs per method first (loads, caches).
    """

    text: str = "a person jumps forward"
    length: int = 196
    repeats: int = 5
    ddpm_repeats: int = 3
    warmup: int = 1


@dataclass
class EnvControlOptions:
    """Figure 5 and the environment-response benchmark: prompts, seeds and the φ grid.

    Attributes:
        prompts: captions (jumps); seeds: noise seeds per prompt; length: frames per motion.
        gravity: g_z sweep (m/s², no wind); wind: w_x and w_y sweeps (N, Earth gravity).
        combos: unseen combinations φ, each compared with its single-factor parts.
        alpha: adapter strength of the SimDiff rows (None: each model's ``sampling.json``).
        filmstrip_frames: frames per filmstrip row (0: no filmstrips).
        resamples: bootstrap resamples of the env_response intervals.
        readout_clips: env_response's check of the gravity readout: this many of the split's real jumps with a
            readable flight, read as they are and re-tracked by the simulator under each gravity (0: no check).
    """

    prompts: list[str] = field(default_factory=lambda: ["a person jumps", "a person jumps up in place",
                                                         "a person jumps forward"])
    seeds: int = 4
    length: int = 120
    gravity: list[float] = field(default_factory=lambda: [-1.0, -3.0, -6.0, -9.81, -15.0, -20.0])
    wind: list[float] = field(default_factory=lambda: [-10.0, -5.0, 0.0, 5.0, 10.0])
    combos: list[list[float]] = field(default_factory=lambda: [[-3.0, 7.0, 7.0]])
    alpha: float | None = None
    filmstrip_frames: int = 8
    resamples: int = 1000
    readout_clips: int = 0


@dataclass
class ContactOptions:
    """The contacts report: generated motions per motion type against the corpus's clips of that type.

    Attributes:
        prompts: motion type (a corpus ``motion_type``) → captions; seeds: noise seeds per caption;
        length: frames per generated motion (20 fps).
    """

    prompts: dict[str, list[str]] = field(default_factory=dict)
    seeds: int = 4
    length: int = 160


@dataclass
class EditingOptions:
    """The editing report (:mod:`simdiff.eval.experiments.editing`).

    Attributes:
        replay_type, replay_clips: motion type and number of the split's clips re-played (those with a flight);
        gravity: the gravities they are re-played at (Earth is always added); seeds: seeds per clip;
        keyframe_type, keyframe_clips, keyframe_frames: the clips whose first frames make the keyframes;
        keep: half (``lower`` or ``upper``) → the text ``simdiff edit --keep`` makes the other half of the same clips
        for;
        timeline: segments ``{"text", "seconds", "gravity"?, "wind"?}`` as in ``generate --timeline``.
    """

    replay_type: str = "jump"
    replay_clips: int = 6
    gravity: list[float] = field(default_factory=lambda: [-1.6, -3.7])
    seeds: int = 1
    keyframe_type: str = "walk"
    keyframe_clips: int = 4
    keyframe_frames: int = 100
    keep: dict[str, str] = field(default_factory=dict)
    timeline: list[dict[str, Any]] = field(default_factory=list)


@dataclass
class FollowingOptions:
    """The prompt-following report (:mod:`simdiff.eval.experiments.following`).

    Attributes:
        wordings: the prompt set measured: ``test`` (held-out wordings, reported) or ``val`` (settings are chosen on).
        prompts: set name → ``[{"category", "text", "checks": [...], "reference"?}]``; checks as in
            :mod:`simdiff.eval.detectors`, all must pass; ``reference`` is the same request without the speed word
            (``speed:`` checks compare against it, same seed).
        ground_truth: ``[{"category", "check", "captions": regex, "exclude"?: regex}]``: the split's original clips
            with a matching caption, checked by the detector (its error on real motion).
        seeds: seeds per wording; length: frames per motion (20 fps).
    """

    wordings: str = "test"
    prompts: dict[str, list[dict[str, Any]]] = field(default_factory=dict)
    ground_truth: list[dict[str, Any]] = field(default_factory=list)
    seeds: int = 4
    length: int = 196


@dataclass
class ExperimentConfig:
    """One experiment; see :mod:`simdiff.eval.experiments` for the kinds.

    Attributes:
        name: report folder ``<out_dir>/<name>``.
        kind: one of :data:`KINDS`.
        corpus: HumanML3D-layout corpus (test split, Mean/Std for d_L2).
        paths: model folder per role (:data:`ROLES`).
        models: the methods.
        samplers: samplers per method (table1, fig4: ``ddpm`` and ``ddim``).
        alphas: adapter strengths of SimDiff rows (table2 sweep; table1 ``[0.1, "best"]``).
        best_alpha: table1's best α (None: read from the ``best_alpha_from`` report).
        select_by: table2's rule for the best α: ``balanced`` (mean of min–max scaled FID and Phys-Err), ``fid``, ``phys_err``.
        reuse_rows_from: other reports whose identical rows are copied instead of re-measured.
        ddpm_samples: DDPM rows measure on this many test motions (0: the full protocol; ≥ batch
            size: ``ddpm_replications`` protocol replications of whole batches; fewer: physics
            metrics and time only).
        envs: φ list (retrack); retrack_samples: motions per (method, φ); contacts: the contacts report;
        editing: the editing report; following: the prompt-following report;
        include_ground_truth: retrack also re-tracks the test motions themselves.
        budgets: named override sets, e.g. ``{"quick": {"about": "...", "set": {"protocol.replications": 3}}}``.
        text_encoder: ``auto``, each model's own (the only value; tests inject a stand-in through
            :class:`~simdiff.eval.experiments.runner.Runner`'s ``text_encoder``).
        threads: torch CPU threads while the experiment runs (0: torch's default). On a machine whose
            cores are busy with other jobs, 1 avoids spinning threads slowing everything down.
        smoke: a test or smoke run on stand-ins: the claim rules of the ``full`` budget are not
            enforced and every report says it carries no claim.

    Claim rules (``full`` budget, not ``smoke``; :func:`check`): table1/table2 protocols with
    n ≥ 256 motions per replication (or the whole split) and R ≥ 5; DDPM rows on ≥ 32 motions;
    table2 (which chooses α) on a split other than ``test``.
    """

    name: str
    kind: str
    corpus: str = "data/cmu_corpus"
    paths: dict[str, str] = field(default_factory=dict)
    models: list[ModelSpec] = field(default_factory=list)
    evaluator: EvaluatorSpec = field(default_factory=EvaluatorSpec)
    protocol: ProtocolConfig = field(default_factory=ProtocolConfig)
    split: str = "test"
    samplers: list[str] = field(default_factory=lambda: ["ddim"])
    alphas: list[Any] = field(default_factory=list)
    best_alpha: float | None = None
    best_alpha_from: str = "table2"
    select_by: str = "balanced"
    reuse_rows_from: list[str] = field(default_factory=list)
    ddpm_samples: int = 0
    ddpm_replications: int = 1
    envs: list[list[float]] = field(default_factory=list)
    retrack_samples: int = 16
    include_ground_truth: bool = True
    timing: TimingOptions = field(default_factory=TimingOptions)
    env_control: EnvControlOptions = field(default_factory=EnvControlOptions)
    contacts: ContactOptions = field(default_factory=ContactOptions)
    editing: EditingOptions = field(default_factory=EditingOptions)
    following: FollowingOptions = field(default_factory=FollowingOptions)
    projector: ProjectorSpec = field(default_factory=ProjectorSpec)
    costs: CostModel = field(default_factory=CostModel)
    budgets: dict[str, dict[str, Any]] = field(default_factory=dict)
    seed: int = 0
    device: str = "cpu"
    out_dir: str = "reports"
    text_encoder: str = "auto"
    threads: int = 0
    smoke: bool = False
    budget: str = "full"
    """Set by :func:`load_config` (not in the file): the budget applied."""
    source: str = ""
    """Set by :func:`load_config`: the config file read."""

    def model_path(self, spec: ModelSpec) -> Path:
        """The resolved folder of ``spec`` (absolute)."""
        if spec.path:
            return Path(spec.path).expanduser().resolve()
        if spec.model not in self.paths:
            raise SimdiffError(f"model {spec.name!r} names role {spec.model!r}, which 'paths' does not define "
                               f"(roles: {', '.join(self.paths) or 'none'})")
        return Path(self.paths[spec.model]).expanduser().resolve()

    def resolved_paths(self) -> dict[str, str]:
        """Corpus, evaluator and every role as absolute paths (recorded in the report)."""
        out = {"corpus": str(Path(self.corpus).expanduser().resolve())}
        if self.evaluator.path:
            out["evaluator"] = str(Path(self.evaluator.path).expanduser().resolve())
        for role, path in self.paths.items():
            out[role] = str(Path(path).expanduser().resolve())
        return out


def set_dotted(raw: dict[str, Any], key: str, value: Any) -> None:
    """Set ``raw[a][b][0]...`` for ``key`` ``a.b.0``; list items by index, dict keys created as needed."""
    parts = key.split(".")
    node: Any = raw
    for i, part in enumerate(parts):
        last = i == len(parts) - 1
        if isinstance(node, list):
            if not part.isdigit() or int(part) >= len(node):
                raise SimdiffError(f"--set {key}: {part!r} is not an index of a list of {len(node)}")
            if last:
                node[int(part)] = value
            else:
                node = node[int(part)]
        elif isinstance(node, dict):
            if last:
                node[part] = value
            else:
                node = node.setdefault(part, {})
                if node is None:
                    raise SimdiffError(f"--set {key}: {part!r} is null in the config")
        else:
            raise SimdiffError(f"--set {key}: {'.'.join(parts[:i])!r} is a value, not a group")


def parse_assignment(text: str) -> tuple[str, Any]:
    """``key=value`` → (key, value); the value is read as JSON when it parses, else kept as a string."""
    key, sep, value = text.partition("=")
    if not sep or not key.strip():
        raise SimdiffError(f"--set expects KEY=VALUE, got {text!r}")
    try:
        parsed = json.loads(value)
    except json.JSONDecodeError:
        parsed = value
    return key.strip(), parsed


def load_config(path: str | os.PathLike[str], budget: str | None = None,
                overrides: list[tuple[str, Any]] | None = None) -> ExperimentConfig:
    """Read a config file, apply a budget and dotted overrides, and check it.

    Args:
        path: ``configs/eval_<kind>.json``.
        budget: a key of the file's ``budgets`` (``full`` is always allowed: the file as written).
        overrides: (dotted key, value) pairs applied last.
    """
    from simdiff.model.config import config_from_dict

    path = Path(path)
    if not path.is_file():
        raise SimdiffError(f"{path}: no such config file")
    try:
        raw = json.loads(path.read_text(encoding="utf-8"))
    except json.JSONDecodeError as exc:
        raise SimdiffError(f"{path}: invalid JSON ({exc.msg}, line {exc.lineno})") from None
    if not isinstance(raw, dict):
        from simdiff.model.config import json_kind

        raise SimdiffError(f"{path}: must be a JSON object {{...}}, got {json_kind(raw)}")
    raw = copy.deepcopy(raw)
    budget = budget or "full"
    budgets = raw.get("budgets", {})
    if budget != "full" and budget not in budgets:
        raise SimdiffError(f"{path}: no budget {budget!r}; choose full{''.join(', ' + b for b in budgets if b != 'full')}")
    for key, value in budgets.get(budget, {}).get("set", {}).items():
        set_dotted(raw, key, copy.deepcopy(value))
    for key, value in overrides or []:
        set_dotted(raw, key, value)
    raw["budget"], raw["source"] = budget, str(path)
    try:
        if not isinstance(raw.get("models", []), list):
            raise SimdiffError(f"{path}: models must be a JSON array of objects")
        raw["models"] = [config_from_dict(m, ModelSpec, str(path), f"models.{i}.")
                         for i, m in enumerate(raw.get("models", []))]
        config = config_from_dict(raw, ExperimentConfig, str(path))
    except TypeError as exc:  # a required field missing
        raise SimdiffError(f"{path}: {exc}") from None
    check(config, path)
    return config


def check(config: ExperimentConfig, origin: str | os.PathLike[str] = "config") -> None:
    """Values every kind relies on; raises :class:`SimdiffError` naming the bad one."""
    if config.kind not in KINDS:
        raise SimdiffError(f"{origin}: unknown experiment kind {config.kind!r}; choose one of {', '.join(KINDS)}")
    bad = [s for s in config.samplers if s not in SAMPLERS]
    if bad or not config.samplers:
        raise SimdiffError(f"{origin}: sampler {bad[0] if bad else '(none)'!r} is not one of {', '.join(SAMPLERS)}")
    for a in config.alphas:
        if not (isinstance(a, (int, float)) or a == "best"):
            raise SimdiffError(f"{origin}: alpha {a!r} must be a number or \"best\"")
    if config.select_by not in ("balanced", "fid", "phys_err"):
        raise SimdiffError(f"{origin}: select_by {config.select_by!r} must be balanced, fid or phys_err")
    for role in config.paths:
        if role not in ROLES:
            raise SimdiffError(f"{origin}: unknown model role {role!r} in paths; choose from {', '.join(ROLES)}")
    for spec in config.models:
        if not spec.path and not spec.model:
            raise SimdiffError(f"{origin}: model {spec.name!r} needs 'model' (a role) or 'path'")
        if spec.model and not spec.path and spec.model not in config.paths:
            raise SimdiffError(f"{origin}: model {spec.name!r} names role {spec.model!r}, which 'paths' does not define")
        if spec.env_guidance is not None and not 0.0 <= float(spec.env_guidance) < float("inf"):
            raise SimdiffError(f"{origin}: model {spec.name!r} env_guidance must be a finite number ≥ 0, "
                               f"got {spec.env_guidance!r}")
        if spec.samplers is not None:
            extra = [s for s in spec.samplers if s not in config.samplers]
            if extra or not spec.samplers:
                raise SimdiffError(f"{origin}: model {spec.name!r} sampler {extra[0] if extra else '(none)'!r} is not "
                                   f"one of the table's samplers ({', '.join(config.samplers)})")
        if spec.compare_to is not None and spec.compare_to not in [m.name for m in config.models if m is not spec]:
            raise SimdiffError(f"{origin}: model {spec.name!r} compare_to {spec.compare_to!r} names no other model")
    for env in config.envs + config.env_control.combos:
        if len(env) != 3:
            raise SimdiffError(f"{origin}: environment {env!r} must be 3 numbers (g_z, w_x, w_y)")
    if config.ddpm_samples < 0 or config.ddpm_replications < 1:
        raise SimdiffError(f"{origin}: ddpm_samples must be >= 0 and ddpm_replications >= 1")
    if config.threads < 0:
        raise SimdiffError(f"{origin}: threads must be >= 0, got {config.threads}")
    if config.text_encoder != "auto":
        raise SimdiffError(f"{origin}: text_encoder {config.text_encoder!r} must be \"auto\" (each model's own encoder)")
    if config.projector.backend not in ("process", "serial"):
        raise SimdiffError(f"{origin}: projector backend {config.projector.backend!r} must be process or serial")
    if config.kind == "table2" and config.split == "test" and not config.smoke:
        raise SimdiffError(f"{origin}: table2 chooses α, so it must run on the val split, not {config.split!r} "
                           "(table1 reports the chosen α on test)")
    problems = claim_problems(config)
    if problems and config.budget == "full" and not config.smoke:
        raise SimdiffError(f"{origin}: the full budget must carry a claim: " + "; ".join(problems)
                           + " (use a named budget such as quick, or smoke: true, for smaller runs)")


def claim_problems(config: ExperimentConfig) -> list[str]:
    """Why ``config`` cannot carry a claim (empty: it can); see :class:`ExperimentConfig`."""
    from simdiff.eval.protocol import claim_problems as protocol_problems

    out: list[str] = []
    if config.kind in ("table1", "table2", "heldout"):
        out += [f"protocol.{p}" for p in protocol_problems(config.protocol, None)]
    if config.kind == "table1" and "ddpm" in config.samplers and 0 < config.ddpm_samples < 32:
        out.append(f"ddpm_samples={config.ddpm_samples} < 32")
    return out
