"""The paper's experiments, one command each, written into ``<out_dir>/<name>/``.

Kinds (``configs/eval_<kind>.json``):

* ``table1``: ground truth, MDM, PhysDiff and SimDiff with DDPM and DDIM; T2M metrics
  (R-precision top-1/2/3, FID, MM-Dist, Diversity, MultiModality) and physics metrics
  (penetration, floating, sliding, skate ratio), mean ± 95% CI over replications; SimDiff at
  α = 0.1 and at the best α of table2 (:mod:`.table1`).
* ``table2``: SimDiff's adapter-scale sweep α, same metrics, and the best α (:mod:`.table2`).
* ``fig4``: inference time per motion at batch 1, methods × samplers, ratios to MDM-DDIM (:mod:`.fig4`).
* ``fig5``: environment control: jump apex vs gravity, drift vs wind, an unseen combination,
  filmstrips; MDM as the env-blind reference (:mod:`.fig5`).
* ``retrack``: closed loop: generated motions re-tracked in the simulator under their φ (:mod:`.retrack`).
* ``env_response``: each generated response to φ against the simulator's response of the same
  Earth motion: sign agreement, slope ratio, additivity (:mod:`.env_response`).
* ``contacts``: sliding, skate ratio, joint speeds and root accelerations of the written joints per motion type,
  with and without the foot cleanup, against real mocap of the type (:mod:`.contacts`).
* ``editing``: real clips re-played under other gravities, keyframes taken from real clips, one timeline
  (:mod:`.editing`).
* ``following``: prompt following per category (direction, turning, counts, in place, body side, speed, posture,
  sequences) by kinematic detectors, on real clips and on held-out wordings (:mod:`.following`).
* ``heldout``: text fidelity on the test captions no train clip has, next to all test captions (:mod:`.heldout`).

Each report folder holds ``report.json`` (config, resolved paths, provenance, budget, rows),
``report.md`` (tables, provenance), figures, and ``rows/`` (one file per finished row; a rerun
skips them, see :mod:`.runner`). :func:`run_all` runs them in dependency order.
"""

from __future__ import annotations

import dataclasses
import os
from pathlib import Path
from types import ModuleType
from typing import Any

from simdiff.fsio import write_text
from simdiff.errors import SimdiffError
from simdiff.eval.experiments import (contacts, editing, env_response, fig4, fig5, following, heldout, retrack,
                                      table1, table2)
from simdiff.eval.experiments.config import KINDS, ExperimentConfig, ModelSpec, load_config
from simdiff.eval.experiments.provenance import load_average, now
from simdiff.eval.experiments.report import duration, header
from simdiff.eval.experiments.runner import RowPlan, Runner

__all__ = ["KINDS", "ORDER", "ExperimentConfig", "ModelSpec", "Runner", "load_config", "plan_experiment", "run_all",
           "run_experiment"]

MODULES: dict[str, ModuleType] = {"table1": table1, "table2": table2, "fig4": fig4, "fig5": fig5, "retrack": retrack,
                                  "env_response": env_response, "contacts": contacts, "editing": editing,
                                  "following": following, "heldout": heldout}
ORDER: tuple[str, ...] = ("table2", "table1", "fig4", "fig5", "retrack", "env_response", "contacts", "editing",
                          "following", "heldout")
"""Run order of :func:`run_all`: table2 first, so table1 finds the best α and reuses its rows."""


def run(runner: Runner) -> dict[str, Any]:
    """Measure every row of ``runner``'s experiment and write its report; returns the report."""
    from simdiff.model.checkpoint import atomic_write_json

    c = runner.config
    module = MODULES[c.kind]
    if not c.models:
        raise SimdiffError(f"experiment {c.name!r} lists no models")
    import torch

    plans = module.plan(runner)
    if any(runner.status(p)[0] == "measure" for p in plans):
        runner.preflight(needs_evaluator=c.kind in ("table1", "table2", "heldout"), needs_corpus=c.kind != "env_response")
    threads = torch.get_num_threads()
    if c.threads:
        torch.set_num_threads(c.threads)
    try:
        rows = runner.execute(plans)
    finally:
        runner.close()
        torch.set_num_threads(threads)
    runner.provenance["machine"]["load_avg_end"] = load_average()
    report = {"name": c.name, "kind": c.kind, "provenance": {**runner.provenance, "finished": now()},
              "budget": budget_info(c), "paths": c.resolved_paths(), "config": dataclasses.asdict(c), "rows": rows}
    body = module.finish(runner, report)
    atomic_write_json(report, runner.out / "report.json")
    write_text(runner.out / "report.md", "\n".join(header(report, module.TITLE) + body) + "\n")
    return report


def budget_info(config: ExperimentConfig) -> dict[str, Any]:
    """The budget applied: name, what it means, its overrides."""
    entry = config.budgets.get(config.budget, {})
    about = entry.get("about") or ("the config as written" if config.budget == "full" else "")
    return {"name": config.budget, "about": about, "set": entry.get("set", {})}


def run_experiment(path: str | os.PathLike[str], *, budget: str | None = None, overrides: list[tuple[str, Any]] | None = None,
                   projector: Any = None, command: list[str] | None = None, progress: bool = True,
                   text_encoder: Any = None) -> dict[str, Any]:
    """Load a config (budget, overrides), run it, write the report; returns the report.

    ``projector`` and ``text_encoder`` (encoder name → encoder) are injected stand-ins (see :class:`Runner`).
    """
    config = load_config(path, budget, overrides)
    return run(Runner(config, projector=projector, command=command, progress=progress, text_encoder=text_encoder))


def plan_experiment(path: str | os.PathLike[str], *, budget: str | None = None,
                    overrides: list[tuple[str, Any]] | None = None) -> list[dict[str, Any]]:
    """What a run would do: per row its key, state (cached / reuse / measure) and estimated seconds."""
    config = load_config(path, budget, overrides)
    runner = Runner(config, progress=False)
    plans: list[RowPlan] = MODULES[config.kind].plan(runner)
    out = []
    for p in plans:
        state, _ = runner.status(p)
        out.append({"experiment": config.name, "key": p.key, "state": state,
                    "estimate_s": p.estimate_s if state == "measure" else 0.0})
    return out


def config_path(configs: str | os.PathLike[str], kind: str) -> Path:
    """``<configs>/eval_<kind>.json``."""
    path = Path(configs) / f"eval_{kind}.json"
    if not path.is_file():
        raise SimdiffError(f"{path}: no such config file (give the configs folder with --configs DIR)")
    return path


def run_all(configs: str | os.PathLike[str] = "configs", *, budget: str | None = None,
            overrides: list[tuple[str, Any]] | None = None, only: list[str] | None = None, projector: Any = None,
            command: list[str] | None = None, progress: bool = True, log: Any = print,
            text_encoder: Any = None) -> list[dict[str, Any]]:
    """Run every kind of :data:`ORDER` (or ``only`` those) in order; returns their reports.

    An override whose first key an experiment's config does not use (``env_control`` for table1) is
    still applied: every config accepts every field.
    """
    kinds = [k for k in ORDER if not only or k in only]
    bad = [k for k in only or [] if k not in KINDS]
    if bad:
        raise SimdiffError(f"unknown experiment {bad[0]!r}; choose from {', '.join(KINDS)}")
    reports = []
    for i, kind in enumerate(kinds, 1):
        path = config_path(configs, kind)
        est = sum(r["estimate_s"] for r in plan_experiment(path, budget=budget, overrides=overrides))
        log(f"[{i}/{len(kinds)}] {kind}: {path} (estimated {duration(est)} to measure)")
        report = run_experiment(path, budget=budget, overrides=overrides, projector=projector, command=command,
                                progress=progress, text_encoder=text_encoder)
        log(f"[{i}/{len(kinds)}] {kind}: {len(report['rows'])} rows → {Path(report['config']['out_dir']) / report['name'] / 'report.md'}")
        reports.append(report)
    return reports
