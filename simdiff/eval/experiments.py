"""Experiment runners that write the paper's tables and figures into ``reports/<name>/``.

One JSON config (``configs/eval_*.json``) → one report folder::

    reports/<name>/report.json   config, provenance, every row measured
    reports/<name>/report.md     the table (mean ± 95% CI) and provenance
    reports/<name>/<name>.png    figures (fig4, fig5)
    reports/<name>/rows/*.json   one file per finished row (resume: finished rows are skipped)

Kinds (rows are ``model × environment`` or a sweep; nothing is filled in that was not run):

* ``table1``: T2M protocol + physics metrics + seconds per sample for each model at its φ
  (default Earth), plus the ground-truth row.
* ``table2``: the same for each model under each φ in ``envs``, with closed-loop
  re-tracking success when ``retrack_samples`` > 0.
* ``fig4``: φ sweep (``envs``) per model: physics metrics and motion statistics (peak root
  height, airborne fraction, horizontal drift) of generated motions, plotted against g_z or wind.
* ``fig5``: adapter-strength sweep (``alphas``): FID / R-precision / physics vs α.
* ``retrack``: generate under φ, replay in the simulator under the same φ; success rate,
  d_L2, tracking error.

Provenance in every report: the command line, the git commit (and whether the tree was
dirty), the seed, the machine (host, platform, CPU count, torch version, device).
"""

from __future__ import annotations

import dataclasses
import datetime as dt
import json
import os
import platform
import subprocess
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import torch

from simdiff.errors import SimdiffError
from simdiff.eval.protocol import ProtocolConfig, evaluate_t2m, generator_fn

KINDS: tuple[str, ...] = ("table1", "table2", "fig4", "fig5", "retrack")


@dataclass
class ModelSpec:
    """A model row.

    Attributes:
        name: row label.
        path: model folder (model.safetensors + config.json).
        env: φ for SimDiff models (None: Earth); env_index for categorical ones.
        alpha: adapter strength.
        sampler, steps, guidance: sampling options.
        physdiff: a :class:`simdiff.baselines.physdiff.PhysDiffConfig` as a dict → PhysDiff sampling.
    """

    name: str
    path: str
    env: list[float] | None = None
    env_index: int | None = None
    alpha: float = 1.0
    sampler: str = "ddim"
    steps: int | None = None
    guidance: float = 2.5
    physdiff: dict[str, Any] | None = None


@dataclass
class EvaluatorSpec:
    """Which evaluator: ``ours`` (``path``) or ``t2m`` (``path`` = finest.tar, ``glove``, ``meta`` folders)."""

    kind: str = "ours"
    path: str = ""
    glove: str | None = None
    meta: str | None = None


@dataclass
class ExperimentConfig:
    """One experiment (see module docstring).

    Attributes:
        text_encoder: ``auto`` (each model's own) or ``hash`` (deterministic stand-in; tests only).
        retrack_samples: motions per (model, φ) replayed in the simulator (table2, retrack).
        residual_bound: tracker residual bound for re-tracking.
    """

    name: str
    kind: str
    corpus: str
    models: list[ModelSpec] = field(default_factory=list)
    evaluator: EvaluatorSpec = field(default_factory=EvaluatorSpec)
    protocol: ProtocolConfig = field(default_factory=ProtocolConfig)
    split: str = "test"
    envs: list[list[float]] = field(default_factory=list)
    alphas: list[float] = field(default_factory=list)
    retrack_samples: int = 0
    residual_bound: float = 0.5
    seed: int = 0
    device: str = "cpu"
    out_dir: str = "reports"
    text_encoder: str = "auto"


def load_config(path: str | os.PathLike[str]) -> ExperimentConfig:
    """Read a ``configs/eval_*.json`` file."""
    from simdiff.model.config import config_from_dict

    path = Path(path)
    if not path.is_file():
        raise SimdiffError(f"{path}: no such config file")
    try:
        raw = json.loads(path.read_text(encoding="utf-8"))
    except json.JSONDecodeError as exc:
        raise SimdiffError(f"{path}: invalid JSON ({exc.msg}, line {exc.lineno})") from None
    raw["models"] = [config_from_dict(m, ModelSpec) for m in raw.get("models", [])]
    config = config_from_dict(raw, ExperimentConfig)
    if config.kind not in KINDS:
        raise SimdiffError(f"{path}: unknown experiment kind {config.kind!r}; choose one of {', '.join(KINDS)}")
    return config


def provenance(seed: int, device: str, command: list[str] | None = None) -> dict[str, Any]:
    """Command, git commit, seed and machine of this run."""
    root = Path(__file__).resolve().parents[2]

    def git(*args: str) -> str | None:
        try:
            return subprocess.run(["git", *args], cwd=root, capture_output=True, text=True, timeout=10, check=True).stdout.strip()
        except (OSError, subprocess.SubprocessError):
            return None

    status = git("status", "--porcelain", "--untracked-files=no")
    dev = torch.device(device)
    return {
        "command": " ".join(command if command is not None else sys.argv),
        "git_commit": git("rev-parse", "HEAD"),
        "git_dirty": None if status is None else bool(status),
        "seed": seed,
        "machine": {"host": platform.node(), "platform": platform.platform(), "python": platform.python_version(),
                    "cpus": os.cpu_count(), "torch": torch.__version__, "device": str(dev),
                    "device_name": torch.cuda.get_device_name(dev) if dev.type == "cuda" else platform.processor() or "cpu"},
        "started": dt.datetime.now(dt.timezone.utc).isoformat(timespec="seconds"),
    }


class Runner:
    """Loads models/evaluator/corpus once and measures rows; finished rows are cached in ``rows/``."""

    def __init__(self, config: ExperimentConfig, *, projector: Any = None, command: list[str] | None = None,
                 progress: bool = True) -> None:
        self.config = config
        self.out = Path(config.out_dir) / config.name
        self.rows_dir = self.out / "rows"
        self.projector = projector
        self.progress = progress
        self.provenance = provenance(config.seed, config.device, command)
        self._models: dict[str, Any] = {}
        self._evaluator: Any = None
        self._dataset: Any = None

    # --- resources ------------------------------------------------------------------------
    def _text_encoder(self, name: str) -> Any:
        if self.config.text_encoder == "hash":
            from simdiff.train.testing import HashTextEncoder

            return HashTextEncoder()
        from simdiff.text.base import load_text_encoder

        return load_text_encoder(name, self.config.device)

    def model(self, spec: ModelSpec) -> Any:
        if spec.path not in self._models:
            from simdiff.model import MotionGenerator

            gen = MotionGenerator.load(spec.path, self.config.device, load_text=False)
            gen.text_encoder = self._text_encoder(gen.config.text_encoder)
            self._models[spec.path] = gen
        return self._models[spec.path]

    @property
    def evaluator(self) -> Any:
        if self._evaluator is None:
            spec = self.config.evaluator
            if spec.kind == "ours":
                from simdiff.eval.evaluator import OurEvaluator, load_evaluator

                model = load_evaluator(spec.path, self.config.device)
                self._evaluator = OurEvaluator(model, self._text_encoder(model.config.text_encoder))
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
        if self._dataset is None:
            from simdiff.data.humanml3d import HumanML3D

            self._dataset = HumanML3D(self.config.corpus, self.config.split, seed=self.config.seed)
        return self._dataset

    # --- rows -----------------------------------------------------------------------------
    def row(self, key: str, measure: Any) -> dict[str, Any]:
        """The cached row ``key`` or ``measure()`` written atomically."""
        from simdiff.model.checkpoint import atomic_write_json

        path = self.rows_dir / f"{key}.json"
        if path.is_file():
            return json.loads(path.read_text(encoding="utf-8"))
        start = time.perf_counter()
        value = {"key": key, **measure(), "wall_s": None}
        value["wall_s"] = round(time.perf_counter() - start, 3)
        atomic_write_json(value, path)
        return value

    def protocol_row(self, spec: ModelSpec, env: list[float] | None = None, alpha: float | None = None) -> dict[str, Any]:
        from simdiff.baselines.physdiff import PhysDiffConfig
        from simdiff.model.config import config_from_dict

        gen = self.model(spec)
        phys = None
        if spec.physdiff is not None:
            phys = config_from_dict(spec.physdiff, PhysDiffConfig)
            if env is not None:
                phys.env = tuple(env)
        fn = generator_fn(gen, env=env if env is not None else spec.env, env_index=spec.env_index,
                          alpha=spec.alpha if alpha is None else alpha, sampler=spec.sampler, steps=spec.steps,
                          guidance=spec.guidance, physdiff=phys, projector=self.projector)
        result = evaluate_t2m(self.evaluator, self.dataset, fn, self.config.protocol, self.progress)
        return {"model": spec.name, "env": env or spec.env, "alpha": spec.alpha if alpha is None else alpha,
                "summary": result["summary"]["generated"], "replications": [r["generated"] for r in result["replications"]],
                "s_per_sample": float(np.mean([r["gen_s_per_sample"] for r in result["replications"]])),
                "samples_per_replication": result["samples_per_replication"]}

    def gt_row(self) -> dict[str, Any]:
        result = evaluate_t2m(self.evaluator, self.dataset, None, self.config.protocol, self.progress)
        return {"model": "ground truth", "summary": result["summary"]["ground_truth"],
                "samples_per_replication": result["samples_per_replication"]}

    def motion_row(self, spec: ModelSpec, env: list[float], n: int = 32) -> dict[str, Any]:
        """Physics metrics and motion statistics of ``n`` generated test captions under ``env``."""
        from simdiff.motion.features import features_to_joints
        from simdiff.motion.metrics import physics_metrics

        captions, lengths = self._captions(n)
        fn = generator_fn(self.model(spec), env=env, env_index=spec.env_index, alpha=spec.alpha, sampler=spec.sampler,
                          steps=spec.steps, guidance=spec.guidance)
        feats = fn(captions, lengths, self.config.seed)
        joints = np.asarray(features_to_joints(feats.double())).astype(np.float64)
        stats = motion_statistics(joints, lengths)
        return {"model": spec.name, "env": env, "physics": physics_metrics(joints, np.asarray(lengths)), "motion": stats}

    def retrack_row(self, spec: ModelSpec, env: list[float]) -> dict[str, Any]:
        """Generate ``retrack_samples`` motions under φ and replay them in the simulator under φ."""
        from simdiff.data.augment.projector import SimProjector
        from simdiff.motion.features import extend_last_frame, features_to_joints
        from simdiff.sim.env import Environment

        n = self.config.retrack_samples
        captions, lengths = self._captions(n)
        fn = generator_fn(self.model(spec), env=env, env_index=spec.env_index, alpha=spec.alpha, sampler=spec.sampler,
                          steps=spec.steps, guidance=spec.guidance)
        feats = fn(captions, lengths, self.config.seed).double().numpy()
        motions = [extend_last_frame(np.asarray(features_to_joints(f[:L])), f[:L]) for f, L in zip(feats, lengths)]
        stats_dir = str(self.config.corpus)
        projector = self.projector or SimProjector(stats_dir, 0, "process", self.config.residual_bound)
        infos = [info for _, info in projector(motions, [Environment(*env)] * n)]
        getattr(projector, "close", lambda: None)() if self.projector is None else None
        get = lambda i, k, d=float("nan"): (i.get(k, d) if isinstance(i, dict) else getattr(i, k, d))  # noqa: E731
        ok = [bool(get(i, "success", False)) for i in infos]
        return {"model": spec.name, "env": env, "samples": n, "success_rate": float(np.mean(ok)),
                "d_l2_mean": float(np.nanmean([get(i, "d_l2") for i in infos])) if infos else None,
                "err_mm_mean": float(np.nanmean([get(i, "err_mm") for i in infos])) if infos else None}

    def _captions(self, n: int) -> tuple[list[str], list[int]]:
        rng = np.random.default_rng([self.config.seed, 99])
        items = [self.dataset.get(int(i) % len(self.dataset), rng) for i in rng.permutation(max(n, len(self.dataset)))[:n]]
        return [it["caption"] for it in items], [int(it["length"]) for it in items]

    # --- experiments ----------------------------------------------------------------------
    def run(self) -> dict[str, Any]:
        """Measure every row of the experiment and write the report; returns it."""
        c = self.config
        if not c.models:
            raise SimdiffError(f"experiment {c.name!r} lists no models")
        rows: list[dict[str, Any]] = []
        envs = c.envs or [[-9.81, 0.0, 0.0]]
        if c.kind == "table1":
            rows.append(self.row("ground_truth", self.gt_row))
            rows += [self.row(f"{m.name}", lambda m=m: self.protocol_row(m)) for m in c.models]
        elif c.kind == "table2":
            for env in envs:
                for m in c.models:
                    rows.append(self.row(_key(m.name, env), lambda m=m, env=env: self.protocol_row(m, env)))
                    if c.retrack_samples > 0:
                        rows.append(self.row(_key(m.name, env, "retrack"), lambda m=m, env=env: self.retrack_row(m, env)))
        elif c.kind == "fig4":
            rows += [self.row(_key(m.name, env, "motion"), lambda m=m, env=env: self.motion_row(m, env)) for m in c.models for env in envs]
        elif c.kind == "fig5":
            if not c.alphas:
                raise SimdiffError("fig5 needs a list of 'alphas'")
            rows += [self.row(f"{m.name}_alpha{a:g}", lambda m=m, a=a: self.protocol_row(m, alpha=a)) for m in c.models for a in c.alphas]
        elif c.kind == "retrack":
            if c.retrack_samples < 1:
                raise SimdiffError("retrack needs 'retrack_samples' >= 1")
            rows += [self.row(_key(m.name, env, "retrack"), lambda m=m, env=env: self.retrack_row(m, env)) for m in c.models for env in envs]
        return self.write(rows)

    def write(self, rows: list[dict[str, Any]]) -> dict[str, Any]:
        from simdiff.model.checkpoint import atomic_write_json

        prov = {**self.provenance, "finished": dt.datetime.now(dt.timezone.utc).isoformat(timespec="seconds")}
        report = {"name": self.config.name, "kind": self.config.kind, "provenance": prov,
                  "config": dataclasses.asdict(self.config), "rows": rows}
        atomic_write_json(report, self.out / "report.json")
        if self.config.kind in ("fig4", "fig5"):
            report["figure"] = str(plot(report, self.out / f"{self.config.name}.png"))
        (self.out / "report.md").write_text(markdown(report), encoding="utf-8")
        return report


def _key(name: str, env: list[float], suffix: str = "") -> str:
    g, wx, wy = env
    return f"{name}_g{g:g}_wx{wx:g}_wy{wy:g}" + (f"_{suffix}" if suffix else "")


def motion_statistics(joints: np.ndarray, lengths: list[int]) -> dict[str, float]:
    """Mean over samples of: peak root height (m), airborne fraction (lowest joint > 5 cm), horizontal root drift (m)."""
    peak, air, drift = [], [], []
    for j, n in zip(joints, lengths):
        j = j[:n]
        peak.append(float(j[:, 0, 1].max()))
        air.append(float((j[:, :, 1].min(axis=1) > 0.05).mean()))
        drift.append(float(np.linalg.norm(j[-1, 0, [0, 2]] - j[0, 0, [0, 2]])))
    return {"peak_root_height_m": float(np.mean(peak)), "airborne_fraction": float(np.mean(air)),
            "drift_m": float(np.mean(drift))}


METRIC_ORDER = ("r_precision_top1", "r_precision_top2", "r_precision_top3", "fid", "mm_dist", "diversity", "multimodality",
                "penetration", "floating", "sliding", "skate_ratio")


def markdown(report: dict[str, Any]) -> str:
    """The report as Markdown: provenance, then one table of the measured rows."""
    p = report["provenance"]
    m = p["machine"]
    lines = [f"# {report['name']} ({report['kind']})", "",
             f"* command: `{p['command']}`", f"* git commit: {p['git_commit']}{' (dirty tree)' if p['git_dirty'] else ''}",
             f"* seed: {p['seed']}", f"* machine: {m['host']}, {m['platform']}, {m['cpus']} CPUs, torch {m['torch']}, {m['device']} ({m['device_name']})",
             f"* started {p['started']}, finished {p['finished']}", ""]
    proto = [r for r in report["rows"] if "summary" in r]
    if proto:
        keys = [k for k in METRIC_ORDER if any(k in r["summary"] for r in proto)]
        lines += ["| row | env | α | " + " | ".join(keys) + " | s/sample |", "|" + "---|" * (len(keys) + 4)]
        for r in proto:
            cells = [f"{r['summary'][k]['mean']:.4g} ± {r['summary'][k]['ci95']:.2g}" if k in r["summary"] else "—" for k in keys]
            sps = f"{r['s_per_sample']:.3g}" if "s_per_sample" in r else "—"
            lines.append(f"| {r['model']} | {r.get('env') or '—'} | {r.get('alpha', '—')} | " + " | ".join(cells) + f" | {sps} |")
        lines.append("")
    other = [r for r in report["rows"] if "summary" not in r]
    if other:
        lines += ["| row | env | measured |", "|---|---|---|"]
        for r in other:
            vals = {k: v for k, v in r.items() if k not in ("key", "model", "env")}
            lines.append(f"| {r['model']} | {r.get('env')} | `{json.dumps(vals, sort_keys=True, default=float)}` |")
    if report.get("figure"):
        lines += ["", f"![{report['name']}]({Path(report['figure']).name})"]
    return "\n".join(lines) + "\n"


def plot(report: dict[str, Any], path: Path) -> Path:
    """Figure of a sweep: fig4 metrics vs the varied φ component, fig5 metrics vs α."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = report["rows"]
    fig, axes = plt.subplots(1, 3, figsize=(12, 3.4))
    if report["kind"] == "fig4":
        series = [("motion", "peak_root_height_m"), ("motion", "airborne_fraction"), ("physics", "penetration")]
        for ax, (group, key) in zip(axes, series):
            for name in dict.fromkeys(r["model"] for r in rows):
                mine = [r for r in rows if r["model"] == name]
                x = [_varied(r["env"]) for r in mine]
                ax.plot(x, [r[group][key] for r in mine], "o-", label=name)
            ax.set_xlabel("g_z (m/s²) / wind (N)")
            ax.set_title(key)
    else:
        series = ["fid", "r_precision_top3", "penetration"]
        for ax, key in zip(axes, series):
            for name in dict.fromkeys(r["model"] for r in rows):
                mine = [r for r in rows if r["model"] == name and key in r["summary"]]
                ax.errorbar([r["alpha"] for r in mine], [r["summary"][key]["mean"] for r in mine],
                            yerr=[r["summary"][key]["ci95"] for r in mine], fmt="o-", label=name)
            ax.set_xlabel("adapter strength α")
            ax.set_title(key)
    axes[0].legend(fontsize=7)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


def _varied(env: list[float]) -> float:
    g, wx, wy = env
    return wx if wx else wy if wy else g


def run_experiment(path: str | os.PathLike[str], *, projector: Any = None, command: list[str] | None = None,
                   progress: bool = True, **overrides: Any) -> dict[str, Any]:
    """Load a config file, apply ``overrides`` (field=value), run it, write the report."""
    config = load_config(path)
    for key, value in overrides.items():
        if value is not None:
            setattr(config, key, value)
    return Runner(config, projector=projector, command=command, progress=progress).run()
