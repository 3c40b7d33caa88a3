"""The seven stages: each has ``settings(ctx)`` (what its key hashes) and ``run(ctx)`` (returns a summary)."""

from __future__ import annotations

import dataclasses
import shutil
import time
from pathlib import Path
from typing import Any

from simdiff.errors import SimdiffError
from simdiff.fsio import write_json, write_text
from simdiff.train.pipeline.context import PipelineContext
from simdiff.train.pipeline.currency import folder_digest

STAGES: tuple[str, ...] = ("corpus", "augment", "backbone", "adapters", "evaluator", "evaluation", "export")
UPSTREAM: dict[str, tuple[str, ...]] = {
    "corpus": (), "augment": ("corpus",), "backbone": ("corpus",), "adapters": ("backbone", "augment"),
    "evaluator": ("corpus",), "evaluation": ("adapters", "evaluator"), "export": ("adapters", "evaluation"),
}
OWN_FOLDER: dict[str, str] = {"backbone": "backbone", "adapters": "adapters", "evaluator": "evaluator",
                              "evaluation": "evaluation", "export": "export"}


# --- corpus --------------------------------------------------------------------------------------

def corpus_settings(ctx: PipelineContext) -> dict[str, Any]:
    c = ctx.config.corpus
    if c.path:
        return {"path": str(Path(c.path).resolve()), "digest": folder_digest(c.path)}
    if not c.shared:
        raise SimdiffError("the pipeline needs corpus.path (a corpus or pack folder) or corpus.shared (a shared data root)")
    from simdiff.data.corpus.build import PIPELINE_VERSION

    return {"shared": str(Path(c.shared).resolve()), "licence": c.licence, "captions": c.captions, "mirror": c.mirror,
            "seed": ctx.config.seed, "version": PIPELINE_VERSION}


def run_corpus(ctx: PipelineContext) -> dict[str, Any]:
    c = ctx.config.corpus
    if c.path:
        from simdiff.data.pack import is_pack, unpack

        if is_pack(Path(c.path)):
            return {"unpacked": unpack(c.path, ctx.corpus_dir(), workers=c.workers, progress=ctx.progress)}
        return {"corpus": str(ctx.corpus_dir())}
    from simdiff.data.corpus.build import CorpusConfig, build

    result = build(CorpusConfig(shared=Path(c.shared), out=ctx.corpus_dir(), licence=c.licence, workers=c.workers,
                                seed=ctx.config.seed, captions=c.captions, mirror=c.mirror, progress=ctx.progress))
    return {"clips": len(result.clips), "splits": result.split_counts}


# --- augmentation --------------------------------------------------------------------------------

def augment_settings(ctx: PipelineContext) -> dict[str, Any]:
    a = ctx.config.augment
    if a.path:
        return {"path": str(Path(a.path).resolve()), "digest": folder_digest(a.path)}
    return {k: v for k, v in ctx.section("augment").items() if k not in ("path", "workers")} | {"seed": ctx.config.seed}


def run_augment(ctx: PipelineContext) -> dict[str, Any]:
    a = ctx.config.augment
    if a.path:
        from simdiff.data.pack import is_pack, unpack

        if is_pack(Path(a.path)):
            return {"unpacked": unpack(a.path, ctx.augmented_dir(), workers=a.workers, progress=ctx.progress)}
        return {"augmented": str(ctx.augmented_dir())}
    from simdiff.data.augment import AugmentConfig, augment

    cfg = AugmentConfig(mode=a.mode, conditions=a.conditions, seed=ctx.config.seed, limit=a.limit,
                        shard_size=a.shard_size, residual_bound=a.residual_bound, workers=a.workers,
                        filter=dataclasses.replace(a.filter))
    report = augment(ctx.corpus_dir(), ctx.augmented_dir(), cfg, projector=ctx.projector, progress=ctx.progress)
    return {"kept": report.get("kept"), "pairs": report.get("pairs")}


# --- training ------------------------------------------------------------------------------------

def _train_settings(ctx: PipelineContext, name: str) -> dict[str, Any]:
    return ctx.section(name) | {"seed": ctx.config.seed} | ctx.text_settings()


def backbone_settings(ctx: PipelineContext) -> dict[str, Any]:
    return _train_settings(ctx, "backbone")


def adapters_settings(ctx: PipelineContext) -> dict[str, Any]:
    settings = _train_settings(ctx, "adapters")
    for name in ("env_pairs", "env_pairs_drift"):  # off: hashed as before the setting existed, so runs stay current
        if not settings.get(name):
            settings.pop(name, None)
    return settings


def _train(ctx: PipelineContext, trainer: Any, max_minutes: float) -> dict[str, Any]:
    """Train to the configured steps, or until ``max_minutes`` of wall clock (stopping at a checkpoint)."""
    start = time.monotonic()
    trainer.train_for(max_minutes, progress=ctx.progress)
    tail = trainer.history[-10:]
    return {"step": trainer.step, "steps": trainer.config.train.steps, "wall_s": round(time.monotonic() - start, 2),
            "final_loss": round(sum(tail) / len(tail), 6) if tail else None}


def run_backbone(ctx: PipelineContext) -> dict[str, Any]:
    from simdiff.data.humanml3d import HumanML3D
    from simdiff.model.config import ModelConfig, backbone_preset
    from simdiff.model.provenance import provenance_from_corpus
    from simdiff.train.config import OptimConfig, RunConfig, TrainConfig
    from simdiff.train.trainer import Trainer

    b, seed = ctx.config.backbone, ctx.config.seed
    encoder = ctx.text()
    model = ModelConfig(backbone=backbone_preset(b.size, mask_frames=b.mask_frames, text_dim=encoder.dim),
                        text_encoder=ctx.config.text_encoder)
    train = TrainConfig(mode="backbone", steps=b.steps, batch_size=b.batch_size, seed=seed, ema=b.ema,
                        ema_decay=b.ema_decay, save_every=b.save_every, optim=OptimConfig(lr=b.lr),
                        losses=dataclasses.replace(b.losses), crop=dataclasses.replace(b.crop))
    dataset = HumanML3D(ctx.corpus_dir(), "train", seed=seed)
    trainer = Trainer(ctx.out / "backbone", RunConfig(model=model, train=train), dataset, text_encoder=encoder,
                      device=ctx.device, provenance=provenance_from_corpus(ctx.corpus_dir(), "backbone"))
    return _train(ctx, trainer, b.max_minutes)


def run_adapters(ctx: PipelineContext) -> dict[str, Any]:
    from simdiff.data.augment import open_training_dataset
    from simdiff.model.checkpoint import read_config
    from simdiff.model.config import SimConfig
    from simdiff.model.provenance import provenance_from_corpus, training_provenance
    from simdiff.train.config import OptimConfig, RunConfig, TrainConfig
    from simdiff.train.trainer import Trainer

    a, seed = ctx.config.adapters, ctx.config.seed
    init = ctx.out / "backbone" / "model"
    model = read_config(init)
    model.sim = SimConfig(mode=a.sim_mode)
    train = TrainConfig(mode="adapters", steps=a.steps, batch_size=a.batch_size, seed=seed, ema=a.ema,
                        ema_decay=a.ema_decay, save_every=a.save_every, optim=OptimConfig(lr=a.lr),
                        env_pairs=a.env_pairs, env_pairs_drift=a.env_pairs_drift)
    dataset = open_training_dataset(ctx.augmented_dir(), "train", seed)
    if len(dataset) == 0:
        raise SimdiffError(f"{ctx.augmented_dir()}: the augmented corpus kept no training clip "
                           f"(see its report.md; loosen the filter or augment more clips, e.g. --set augment.limit=64)")
    provenance = training_provenance("adapters", init=init).merged(  # an augmented folder without a record: our corpus
        provenance_from_corpus(ctx.augmented_dir(), "adapters", source=ctx.corpus_dir()))
    trainer = Trainer(ctx.out / "adapters", RunConfig(model=model, train=train), dataset, text_encoder=ctx.text(),
                      device=ctx.device, init_model=init, provenance=provenance)
    return _train(ctx, trainer, a.max_minutes)


# --- evaluator and evaluation --------------------------------------------------------------------

def evaluator_settings(ctx: PipelineContext) -> dict[str, Any]:
    return ctx.section("evaluator") | {"seed": ctx.config.seed} | ctx.text_settings()


def run_evaluator(ctx: PipelineContext) -> dict[str, Any]:
    from simdiff.eval.evaluator import EvaluatorConfig
    from simdiff.eval.train_evaluator import EvaluatorTrainConfig, train_evaluator

    e = ctx.config.evaluator
    cfg = EvaluatorTrainConfig(evaluator=EvaluatorConfig(text_encoder=ctx.config.text_encoder), epochs=e.epochs,
                               batch_size=e.batch_size, lr=e.lr, seed=ctx.config.seed)
    summary = train_evaluator(ctx.corpus_dir(), ctx.out / "evaluator", cfg, text_encoder=ctx.text(), device=ctx.device,
                              progress=ctx.progress)
    return {"epochs": summary["epochs"], "best": summary["best"]}


def evaluation_settings(ctx: PipelineContext) -> dict[str, Any]:
    return ctx.section("evaluation") | {"seed": ctx.config.seed}


def run_evaluation(ctx: PipelineContext) -> dict[str, Any]:
    from simdiff.data.humanml3d import HumanML3D
    from simdiff.eval.evaluator import OurEvaluator
    from simdiff.diffusion.config import SAMPLER_STEPS, SamplingConfig
    from simdiff.eval.protocol import ProtocolConfig, evaluate_t2m, generator_fn
    from simdiff.inference.generator import MotionGenerator

    ev, seed = ctx.config.evaluation, ctx.config.seed
    evaluator = OurEvaluator.load(ctx.out / "evaluator", ctx.device, text_encoder=ctx.text())
    generator = MotionGenerator.load(ctx.out / "adapters" / "model", ctx.device, load_text=False)
    generator.text_encoder = ctx.text()
    dataset = HumanML3D(ctx.corpus_dir(), "test", normalizer=None, seed=seed)
    config = ProtocolConfig(replications=ev.replications, batch_size=ev.batch_size, samples_limit=ev.samples_limit,
                            seed=seed)
    categorical = ctx.config.adapters.sim_mode == "categorical"  # category 0: the source (Earth) clips
    sampling = SamplingConfig(sampler=ev.sampler, steps=ev.steps or SAMPLER_STEPS[ev.sampler], guidance=ev.guidance)
    generate = generator_fn(generator, sampling, env=None if categorical else list(ev.env),
                            env_index=0 if categorical else None)
    result = evaluate_t2m(evaluator, dataset, generate, config, progress=ctx.progress)
    write_json(ctx.out / "evaluation" / "evaluation.json", result)
    gen = result["summary"].get("generated", {})
    return {k: gen[k]["mean"] for k in ("r_precision_top3", "fid", "sliding", "skate_ratio") if k in gen}


# --- export --------------------------------------------------------------------------------------

def export_settings(ctx: PipelineContext) -> dict[str, Any]:
    return ctx.section("export")


def run_export(ctx: PipelineContext) -> dict[str, Any]:
    import json

    from simdiff.inference.coverage import training_captions, write_coverage_table
    from simdiff.model.provenance import PROVENANCE_NAME, read_provenance
    from simdiff.model.shards import shard_model_folder

    out = ctx.out / "export"
    model = out / "model"
    if out.exists():
        shutil.rmtree(out)
    src = ctx.out / "adapters" / "model"
    model.mkdir(parents=True)
    for name in ("config.json", "model.safetensors", PROVENANCE_NAME):
        if name == PROVENANCE_NAME and not (src / name).is_file():
            continue  # a model trained before provenance was recorded: the README says "unknown"
        shutil.copyfile(src / name, model / name)
    write_json(model / "sampling.json", {"alpha": ctx.config.export.alpha, "guidance": ctx.config.evaluation.guidance,
                                         "steps": ctx.config.evaluation.steps, "sampler": ctx.config.evaluation.sampler})
    captions = write_coverage_table(model, training_captions(ctx.corpus_dir(), "train"), ctx.text())
    shards: list[str] = []
    if ctx.config.export.shard_mib > 0:
        shards = shard_model_folder(model, out / "sharded", int(ctx.config.export.shard_mib * 2**20))
    summary_path = ctx.out / "evaluation" / "evaluation.json"
    evaluation = json.loads(summary_path.read_text())["summary"] if summary_path.is_file() else {}
    markers = {s: json.loads((ctx.out / "stages" / f"{s}.json").read_text()).get("summary", {})
               for s in ("backbone", "adapters") if (ctx.out / "stages" / f"{s}.json").is_file()}
    write_json(out / "training.json", {"budget": ctx.config.budget, "seed": ctx.config.seed, "keys": ctx.keys,
                                       "config": dataclasses.asdict(ctx.config), "training": markers,
                                       "evaluation": evaluation})
    provenance = read_provenance(model)
    write_text(model / "README.md", _readme(ctx, markers, evaluation, provenance))
    return {"model": str(model), "shards": shards, "captions": captions["captions"],
            "weights_licence": provenance.weights_licence if provenance is not None else "unknown"}


def _provenance_lines(provenance: Any) -> list[str]:
    """README lines: the weights' licence and what each part was trained on."""
    if provenance is None:
        return ["Weights licence: **unknown** (the trained model folder has no provenance.json).", ""]
    lines = [f"Weights licence: **{provenance.weights_licence}** (the most restrictive licence among the "
             "training data decides; details in `provenance.json`).", "", "Trained on:", ""]
    for part in provenance.trained_on:
        hours = f"{part.hours:.2f} h of original motion" if part.hours is not None else "hours unknown"
        codes = ", ".join(f"{code} {h:.2f} h" for code, h in part.licences.items()) or "licences unknown"
        note = f"; {part.note}" if part.note else ""
        lines.append(f"* {part.what}: `{part.data}` ({', '.join(part.sources) or 'sources unknown'}; {hours}; "
                     f"{codes}{note})")
    return lines + [""]


def _readme(ctx: PipelineContext, markers: dict[str, Any], evaluation: dict[str, Any], provenance: Any = None) -> str:
    cfg = ctx.config
    lines = [f"# simdiff model (pipeline budget `{cfg.budget}`, seed {cfg.seed})", "",
             f"Backbone `{cfg.backbone.size}` ({markers.get('backbone', {}).get('step', '?')} steps of batch "
             f"{cfg.backbone.batch_size}); adapters {markers.get('adapters', {}).get('step', '?')} steps of batch "
             f"{cfg.adapters.batch_size}; text encoder `{cfg.text_encoder}`.",
             f"Corpus: `{ctx.corpus_dir()}`; augmented: `{ctx.augmented_dir()}`.", "",
             *_provenance_lines(provenance),
             "Evaluation (our evaluator, test split, Earth φ; mean over replications):", ""]
    for side in ("generated", "ground_truth"):
        row = evaluation.get(side, {})
        vals = ", ".join(f"{k} {row[k]['mean']:.3f}" for k in ("r_precision_top3", "fid", "sliding", "skate_ratio")
                         if k in row)
        lines.append(f"* {side}: {vals or 'n/a'}")
    lines += ["", "Full settings and stage keys: `../training.json`.", ""]
    return "\n".join(lines)


SETTINGS = {"corpus": corpus_settings, "augment": augment_settings, "backbone": backbone_settings,
            "adapters": adapters_settings, "evaluator": evaluator_settings, "evaluation": evaluation_settings,
            "export": export_settings}
RUN = {"corpus": run_corpus, "augment": run_augment, "backbone": run_backbone, "adapters": run_adapters,
       "evaluator": run_evaluator, "evaluation": run_evaluation, "export": run_export}
