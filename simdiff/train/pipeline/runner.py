"""Plan and run the pipeline: compute every stage's key, skip the current ones, run the rest in order."""

from __future__ import annotations

import dataclasses
import shutil
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

import torch

from simdiff.errors import SimdiffError
from simdiff.fsio import ensure_dir, write_json
from simdiff.train.pipeline.config import PipelineConfig
from simdiff.train.pipeline.context import PipelineContext
from simdiff.train.pipeline.currency import clear_marker, digest, marker_path, read_marker, write_marker
from simdiff.train.pipeline.stages import OWN_FOLDER, RUN, SETTINGS, STAGES, UPSTREAM


@dataclass
class StagePlan:
    """One stage of the plan: ``status`` is ``current`` (skipped), ``resume`` (same key, unfinished) or ``run``."""

    name: str
    key: str
    status: str
    settings: dict[str, Any]


def plan_pipeline(ctx: PipelineContext) -> list[StagePlan]:
    """Keys and statuses of all stages (fills ``ctx.keys``); reads markers only, runs nothing."""
    plans: list[StagePlan] = []
    stale: set[str] = set()
    for name in STAGES:
        settings = SETTINGS[name](ctx)
        key = digest({"stage": name, "settings": settings, "upstream": {u: ctx.keys[u] for u in UPSTREAM[name]}})
        ctx.keys[name] = key
        done = read_marker(ctx.out, name)
        started = read_marker(ctx.out, name, started=True)
        upstream_stale = bool(set(UPSTREAM[name]) & stale)
        if done is not None and done.get("key") == key and not upstream_stale:
            status = "current"
        elif started is not None and started.get("key") == key and not upstream_stale:
            status = "resume"
        else:
            status = "run"
        if status != "current":
            stale.add(name)
        plans.append(StagePlan(name, key, status, settings))
    return plans


def format_plan(plans: list[StagePlan]) -> str:
    """One line per stage: name, status, short key."""
    return "\n".join(f"{p.name:<11} {p.status:<8} {p.key[:12]}" for p in plans)


def _reset(ctx: PipelineContext, name: str, settings: dict[str, Any]) -> None:
    """Drop a stale stage's own outputs (never an input folder given by path).

    The pipeline's own augmented corpus is kept when only ``limit`` or the ``filter`` changed
    (the augmentation then resumes and extends it, or only re-finalises: the keep decision is
    made at finalize); any other change of its settings starts it afresh.
    """
    previous = (read_marker(ctx.out, name) or read_marker(ctx.out, name, started=True) or {}).get("settings")
    clear_marker(ctx.out, name)
    folder = OWN_FOLDER.get(name)
    if name == "augment" and not ctx.config.augment.path and previous is not None:
        def strip(d: dict[str, Any]) -> dict[str, Any]:
            return {k: v for k, v in d.items() if k not in ("limit", "filter")}

        if strip(previous) != strip(settings):
            folder = "augmented"
    if name == "corpus" and ctx.corpus_dir() == ctx.out / "corpus" and ctx.config.corpus.path:
        folder = "corpus"  # an unpacked pack: redo from scratch (a built corpus resumes from its item cache)
    if name == "augment" and ctx.augmented_dir() == ctx.out / "augmented" and ctx.config.augment.path:
        folder = "augmented"
    if folder is not None and (ctx.out / folder).exists():
        shutil.rmtree(ctx.out / folder)


def run_pipeline(config: PipelineConfig, out: str | Path, *, device: torch.device | str = "cpu", text_encoder: Any = None,
                 projector: Any = None, dry_run: bool = False, progress: bool = True,
                 log: Callable[[str], None] = print) -> list[StagePlan]:
    """Run every stale stage of ``config`` into ``out``; returns the plan as it was before running.

    ``dry_run`` prints the plan and runs nothing. A stage whose key changed since its last run
    starts again from nothing; one interrupted with the same key resumes.
    """
    out = Path(out)
    ctx = PipelineContext(out=out, config=config, device=torch.device(device), text_encoder=text_encoder,
                          projector=projector, progress=progress, log=log)
    plans = plan_pipeline(ctx)
    log(format_plan(plans))
    if dry_run:
        return plans
    ensure_dir(out)
    write_json(out / "pipeline_config.json", dataclasses.asdict(config))
    torch.manual_seed(config.seed)
    for i, p in enumerate(plans):
        if p.status == "current":
            log(f"[{i + 1}/{len(plans)}] {p.name}: current, skipped")
            continue
        if p.status == "run":
            _reset(ctx, p.name, p.settings)
        write_marker(out, p.name, {"key": p.key, "settings": p.settings}, started=True)
        log(f"[{i + 1}/{len(plans)}] {p.name}: {'resuming' if p.status == 'resume' else 'running'}")
        start = time.monotonic()
        try:
            summary = RUN[p.name](ctx)
        except SimdiffError as exc:
            raise SimdiffError(f"pipeline stage {p.name}: {exc}") from None
        elapsed = round(time.monotonic() - start, 2)
        write_marker(out, p.name, {"key": p.key, "settings": p.settings, "summary": summary, "elapsed_s": elapsed,
                                   "finished": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())})
        marker_path(out, p.name, started=True).unlink(missing_ok=True)
        log(f"[{i + 1}/{len(plans)}] {p.name}: done in {elapsed:.1f} s")
    return plans
