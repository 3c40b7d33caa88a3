"""``simdiff train backbone|adapters|export-backbone|extrapolate|deepen``: train the MDM backbone, or SimDiff's adapters on
a frozen one; export a SimDiff model's backbone on its own; extrapolate a backbone fine-tune.

Multi-process: ``torchrun --nproc_per_node N -m simdiff train backbone ...`` (gloo on CPU,
nccl on CUDA); ``--batch-size`` is the global batch.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from simdiff.cli.options import MAX_TRAIN_BATCH, SEED, WORKERS, integer, real
from simdiff.cli.main import command_group


def _common(p: argparse.ArgumentParser) -> None:
    data = p.add_mutually_exclusive_group(required=True)
    data.add_argument("--data", type=Path, nargs="+",
                      help="HumanML3D-layout directory (new_joint_vecs/, texts/, Mean.npy, Std.npy, <split>.txt); "
                           "several folders are read as one dataset")
    data.add_argument("--synthetic", type=integer(1, 100_000), metavar="N", help="train on N synthetic clips (smoke tests only)")
    p.add_argument("--split", default="train", help="split file name under --data (default: train)")
    p.add_argument("--source", type=Path, default=None,
                   help="augmented --data only: also train on this source corpus's clips as env_index 0 (binary setting)")
    p.add_argument("--out", type=Path, required=True, help="run folder: checkpoints/, model/ (resumes if it has checkpoints)")
    p.add_argument("--config", type=Path, help="a run config JSON (see configs/); flags below override it")
    p.add_argument("--steps", type=integer(1, 10_000_000), help="total optimiser steps")
    p.add_argument("--batch-size", type=integer(1, MAX_TRAIN_BATCH),
                   help=f"global batch size, 1..{MAX_TRAIN_BATCH}")
    p.add_argument("--lr", type=real(0.0, 1.0, above=True), help="AdamW learning rate (default 1e-4)")
    p.add_argument("--lr-schedule", choices=["constant", "cosine"],
                   help="constant (MDM, the default) or cosine: from --lr down to 0 at --steps")
    p.add_argument("--seed", type=SEED, help="seed for init, data order, noise, dropout (default 10)")
    p.add_argument("--ema", action=argparse.BooleanOptionalAction, default=None, help="keep and export an EMA of the weights")
    p.add_argument("--ema-decay", type=real(0.0, 1.0), help="EMA decay (default 0.9999)")
    p.add_argument("--save-every", type=integer(1, 10_000_000), help="checkpoint period in steps")
    p.add_argument("--device", default="cpu", help="torch device, e.g. cpu, cuda, cuda:1 (default: cpu)")
    p.add_argument("--clip-weights", help="local CLIP ViT-B/32 weights file (with --text-encoder clip)")
    p.add_argument("--text-table", type=Path,
                   help="precomputed caption embeddings (`simdiff train text-table`) instead of loading the text "
                        "encoder's weights (a GPU machine without them)")
    p.add_argument("--max-minutes", type=real(0.0, 1e6), default=0.0,
                   help="stop at the first checkpoint after this much wall clock (0 = run to --steps); resumable")
    p.add_argument("--loader-workers", type=WORKERS, default=0,
                   help="processes that build batches ahead of the training loop (0: none; same batches either way)")
    p.add_argument("--no-resume", action="store_true", help="refuse to continue an existing run folder")
    p.add_argument("--no-progress", action="store_true", help="hide the progress bar")


def register(subparsers: argparse._SubParsersAction) -> None:
    group = command_group(subparsers, "train", "train the diffusion backbone or SimDiff's adapters")
    b = group.add_parser("backbone", help="train the MDM-style backbone from scratch",
                         description="Train the text-to-motion backbone (x0-prediction, cosine schedule, T=1000).")
    _common(b)
    b.add_argument("--size", choices=["mdm", "small", "tiny"], help="network size (default small; mdm = the paper's)")
    b.add_argument("--text-encoder", choices=["minilm", "clip"], help="text encoder (default minilm)")
    b.add_argument("--mask-frames", action=argparse.BooleanOptionalAction, default=None,
                   help="mask padded frames in attention (off reproduces MDM); adds no weights, so it may "
                        "change with --init (the run then fine-tunes the model under the new setting)")
    b.add_argument("--init", type=Path,
                   help="warm start: begin from this model folder's backbone weights (a SimDiff folder gives its "
                        "backbone) with a fresh optimiser; its architecture and text encoder are used")
    b.set_defaults(func=run, mode="backbone")
    a = group.add_parser("adapters", help="train the Sim Encoder and Motion Adapters on a frozen backbone",
                         description="Train SimDiff's Sim Encoder + Motion Adapters; the backbone stays frozen. "
                                     "Dataset items must carry φ ('env' (3,) or 'env_index').")
    _common(a)
    a.add_argument("--init", type=Path, help="backbone model folder (model.safetensors + config.json)")
    a.add_argument("--adapters-init", type=Path,
                   help="warm start: begin from this SimDiff model folder's Sim Encoder and Motion Adapters (same "
                        "sim config) instead of zero-initialised adapters")
    a.add_argument("--sim-mode", choices=["continuous", "categorical"], help="φ as (g_z, w_x, w_y) floats or a category")
    a.add_argument("--num-categories", type=integer(1, 1024), help="number of environment categories (categorical)")
    a.add_argument("--env-pairs", type=real(0.0, 1e3), metavar="WEIGHT",
                   help="weight of the paired φ-difference loss on twin clips (a paired augmentation; 0 = off, "
                        "the paper's loss); see TrainConfig.env_pairs")
    a.add_argument("--env-pairs-drift", type=real(0.0, 1e3), metavar="WEIGHT",
                   help="weight of the twins' mean root-velocity (drift) term, with --env-pairs (0 = off); see "
                        "TrainConfig.env_pairs_drift")
    a.add_argument("--targets", choices=["simulated", "source-anchored", "source-anchored-pairs"],
                   help="training targets: the simulator's replays (default) or the source clip plus the replay's "
                        "change against its Earth twin (-pairs: Earth items without a twin keep the replay); see "
                        "simdiff.data.augment.anchored")
    a.add_argument("--anchor-corpus", type=Path, metavar="PATH",
                   help="with --targets source-anchored or source-anchored-pairs: the corpus the --data folders were "
                        "augmented from (default: each folder's source_corpus.json)")
    a.add_argument("--twin-frames", choices=["equal", "prefix", "overlap"],
                   help="which replays of one source clip are twins for --env-pairs: equal frames only (default), "
                        "all trimmed to their common first frames (prefix), or all kept whole and compared over the "
                        "frames they share (overlap); a low-gravity replay that flies longer is longer than its "
                        "Earth twin; see TrainConfig.twin_frames")
    a.add_argument("--drift-pairs", choices=["all", "wind"],
                   help="which twins the drift term (--env-pairs-drift) compares: all (default) or only those whose "
                        "phi differ in wind; see TrainConfig.drift_pairs")
    a.add_argument("--pair-twins", choices=["all", "wind"],
                   help="which twins the per-frame paired loss (--env-pairs) compares: all (default) or only those "
                        "whose phi differ in wind; see TrainConfig.pair_twins")
    a.add_argument("--cross-twins", type=real(0.0, 1.0), metavar="P",
                   help="share of paired twins (needs --env-pairs) noised from each other's motion, the target "
                        "staying their own: phi then edits the motion x_t shows; see TrainConfig.cross_twins")
    a.add_argument("--cross-match", metavar="REGEX",
                   help="cross only the twin pairs whose caption matches this regular expression (case-insensitive), "
                        "e.g. 'jump|hop|leap'; needs --cross-twins; see TrainConfig.cross_match")
    a.set_defaults(func=run, mode="adapters")
    e = group.add_parser("export-backbone", help="write a SimDiff model's frozen backbone as a backbone-only model",
                         description="Write the backbone of a SimDiff model folder (weights bit-identical, "
                                     "Mean/Std, provenance) as its own model folder: the MDM rows of an evaluation.")
    _model_and_out(e, "SimDiff model folder (model.safetensors + config.json)")
    e.set_defaults(func=run_export)
    x = group.add_parser("extrapolate", help="move a fine-tuned backbone further along its fine-tune (task arithmetic)",
                         description="Write MODEL with its backbone weights at model + LAMBDA x (model - parent): "
                                     "LAMBDA 0 copies MODEL, LAMBDA > 0 goes further in the direction the fine-tune "
                                     "from PARENT moved them. Adapters, Mean/Std, config and sampling.json are "
                                     "MODEL's; extrapolation.json records the recipe.")
    _model_and_out(x, "the fine-tuned model folder (SimDiff or backbone-only)")
    x.add_argument("--parent", type=Path, required=True, help="the model folder it was fine-tuned from")
    x.add_argument("--lam", type=real(-10.0, 10.0), required=True, metavar="LAMBDA", help="extrapolation factor (e.g. 2)")
    x.set_defaults(func=run_extrapolate)
    dp = group.add_parser("deepen", help="insert identity layers into a model's backbone (same output, more depth)",
                          description="Write MODEL with one new transformer layer after each listed backbone layer. "
                                      "The new layers start as the identity (zero attention out-projection and "
                                      "second feed-forward linear; the preceding layer's norm2 affine moves onto "
                                      "them), so the deeper model gives the same x0 until it is trained further "
                                      "(`train backbone --init`). Adapters keep their inputs; new adapter slots are "
                                      "zero. deepening.json records the recipe.")
    _model_and_out(dp, "model folder (SimDiff or backbone-only)")
    dp.add_argument("--after", type=integer(0, 255), nargs="+", metavar="LAYER",
                    help="old layer indices each followed by a new layer (default: every layer, doubling the depth)")
    dp.add_argument("--seed", type=SEED, default=0, help="seed of the new layers' input-side weights (default 0)")
    dp.set_defaults(func=run_deepen)
    pr = group.add_parser("precision", help="store a model's weights as float16 (half the file) or float32",
                          description="Write MODEL with its network weights stored as DTYPE (float16: half the "
                                      "file, each weight within 2^-11 relative; float32). Mean/Std stay float32; "
                                      "loading gives float32 weights either way. precision.json records the "
                                      "recipe.")
    _model_and_out(pr, "model folder (SimDiff or backbone-only)")
    pr.add_argument("--dtype", choices=["float16", "float32"], default="float16", help="stored precision")
    pr.set_defaults(func=run_precision)


def run_export(args: argparse.Namespace) -> int:
    from simdiff.cli.paths import check_separate
    from simdiff.model.checkpoint import export_backbone

    check_separate(args.out, model=args.model)
    print(f"wrote {export_backbone(args.model, args.out)}")
    return 0


def run_deepen(args: argparse.Namespace) -> int:
    from simdiff.cli.paths import check_separate
    from simdiff.model.deepen import deepen_model

    check_separate(args.out, model=args.model)
    print(f"wrote {deepen_model(args.model, args.out, args.after, args.seed)}")
    return 0


def _model_and_out(parser: argparse.ArgumentParser, model_help: str) -> None:
    """``--model`` (the source folder) and ``--out`` of the commands that write a model derived from another."""
    parser.add_argument("--model", type=Path, required=True, help=model_help)
    parser.add_argument("--out", type=Path, required=True, help="output model folder (files in it are replaced)")


def run_precision(args: argparse.Namespace) -> int:
    from simdiff.cli.paths import check_separate
    from simdiff.model.precision import convert_precision

    check_separate(args.out, model=args.model)
    print(f"wrote {convert_precision(args.model, args.out, args.dtype)}")
    return 0


def run_extrapolate(args: argparse.Namespace) -> int:
    from simdiff.cli.paths import check_separate
    from simdiff.model.extrapolate import extrapolate_backbone

    check_separate(args.out, model=args.model, parent=args.parent)
    print(f"wrote {extrapolate_backbone(args.model, args.parent, args.lam, args.out)}")
    return 0


def _run_config(args: argparse.Namespace):
    from simdiff.errors import SimdiffError
    from simdiff.model.checkpoint import read_config
    from simdiff.model.config import PRESETS, SimConfig, backbone_preset, check_model_config
    from simdiff.text.base import text_dim
    from simdiff.train.config import RunConfig, check_train_config, read_run_config

    if args.config is not None:
        config, where = read_run_config(args.config), str(args.config)
    elif (args.out / "train_config.json").is_file():  # continuing a run: start from its config
        where = str(args.out / "train_config.json")
        config = read_run_config(where)
    else:
        config, where = RunConfig(), "the options"
    tc = config.train
    tc.mode = args.mode
    for flag, field in (("steps", "steps"), ("batch_size", "batch_size"), ("seed", "seed"), ("ema", "ema"),
                        ("ema_decay", "ema_decay"), ("save_every", "save_every")):
        if getattr(args, flag) is not None:
            setattr(tc, field, getattr(args, flag))
    if args.lr is not None:
        tc.optim.lr = args.lr
    if args.lr_schedule is not None:
        tc.optim.lr_schedule = args.lr_schedule
    if getattr(args, "env_pairs", None) is not None:
        tc.env_pairs = args.env_pairs
    if getattr(args, "env_pairs_drift", None) is not None:
        tc.env_pairs_drift = args.env_pairs_drift
    if getattr(args, "targets", None) is not None:
        tc.targets = args.targets
    if getattr(args, "twin_frames", None) is not None:
        tc.twin_frames = args.twin_frames
    if getattr(args, "drift_pairs", None) is not None:
        tc.drift_pairs = args.drift_pairs
    if getattr(args, "pair_twins", None) is not None:
        tc.pair_twins = args.pair_twins
    if getattr(args, "cross_twins", None) is not None:
        tc.cross_twins = args.cross_twins
    if getattr(args, "cross_match", None) is not None:
        tc.cross_match = args.cross_match
    from simdiff.data.augment.anchored import TARGETS
    from simdiff.data.augment.dataset import TWIN_FRAMES
    from simdiff.train.config import DRIFT_PAIRS

    if tc.targets not in TARGETS:
        raise SimdiffError(f"train.targets {tc.targets!r}: choose from {', '.join(TARGETS)}")
    if tc.targets != "simulated" and args.mode != "adapters":
        raise SimdiffError(f"targets {tc.targets!r} are for `simdiff train adapters`")
    if getattr(args, "anchor_corpus", None) is not None and tc.targets == "simulated":
        raise SimdiffError(f"--anchor-corpus {args.anchor_corpus}: only with --targets source-anchored or "
                           "source-anchored-pairs")
    if tc.twin_frames not in TWIN_FRAMES:
        raise SimdiffError(f"train.twin_frames {tc.twin_frames!r}: choose from {', '.join(TWIN_FRAMES)}")
    if tc.drift_pairs not in DRIFT_PAIRS:
        raise SimdiffError(f"train.drift_pairs {tc.drift_pairs!r}: choose from {', '.join(DRIFT_PAIRS)}")
    if tc.pair_twins not in DRIFT_PAIRS:
        raise SimdiffError(f"train.pair_twins {tc.pair_twins!r}: choose from {', '.join(DRIFT_PAIRS)}")
    if tc.twin_frames != "equal" and args.mode != "adapters":
        raise SimdiffError(f"twin frames {tc.twin_frames!r} are for `simdiff train adapters`")
    import math  # the same bounds as the options, for values that come from a config file

    if not (isinstance(tc.steps, int) and tc.steps >= 1):
        raise SimdiffError(f"train.steps (--steps) must be a whole number ≥ 1, got {tc.steps!r}")
    if not (isinstance(tc.batch_size, int) and 1 <= tc.batch_size <= MAX_TRAIN_BATCH):
        raise SimdiffError(f"train.batch_size (--batch-size) must be 1..{MAX_TRAIN_BATCH}, got {tc.batch_size!r}")
    lr = tc.optim.lr
    if not (isinstance(lr, (int, float)) and math.isfinite(lr) and 0 < lr <= 1):
        raise SimdiffError(f"train.optim.lr (--lr) must be a number in (0, 1], got {lr!r}")
    if args.mode == "backbone":
        model = config.model
        if args.init is not None:
            if args.size is not None or args.text_encoder is not None:
                raise SimdiffError("--init takes the architecture from the model folder; drop --size and "
                                   "--text-encoder")
            init = read_config(args.init)
            model.backbone, model.text_encoder = init.backbone, init.text_encoder
        if args.size is not None:
            model.backbone = backbone_preset(args.size, mask_frames=model.backbone.mask_frames)
        assert args.size is None or args.size in PRESETS
        if args.text_encoder is not None:
            model.text_encoder = args.text_encoder
        if args.mask_frames is not None:
            model.backbone.mask_frames = args.mask_frames
        model.backbone.text_dim = text_dim(model.text_encoder)
        model.sim = None
    else:
        if args.init is not None:
            init = read_config(args.init)
            config.model.backbone, config.model.text_encoder = init.backbone, init.text_encoder
        if args.adapters_init is not None and args.config is None and config.model.sim is None:
            config.model.sim = read_config(args.adapters_init).sim  # the warm start's sim part, unless a config says
        sim = config.model.sim or SimConfig()
        if args.sim_mode is not None:
            sim.mode = args.sim_mode
        if args.num_categories is not None:
            sim.num_categories = args.num_categories
        config.model.sim = sim
    check_train_config(tc, where)
    check_model_config(config.model, where, prefix="model.")
    return config


def _dataset(args: argparse.Namespace, seed: int, targets: str = "simulated", verbose: bool = True,
             twin_frames: str = "equal"):
    from simdiff.errors import SimdiffError
    from simdiff.train.data import synthetic_dataset

    if args.synthetic is not None:
        if args.synthetic < 1:
            raise SimdiffError("--synthetic needs at least one clip")
        return synthetic_dataset(args.synthetic, frames=60, seed=seed, with_env=args.mode == "adapters")
    from simdiff.data.augment import open_training_dataset

    for folder in args.data:
        if not folder.is_dir():
            raise SimdiffError(f"--data {folder}: not a directory")
        if args.mode == "adapters" and not (folder / "env.json").is_file():
            raise SimdiffError(f"{folder}: adapters train on a simulator-augmented corpus (env.json), see `simdiff data augment`")
    dataset = open_training_dataset(list(args.data), args.split, seed, source=getattr(args, "source", None),
                                    targets=targets, anchor_corpus=getattr(args, "anchor_corpus", None),
                                    twin_frames=twin_frames)
    parts = getattr(dataset, "parts", [dataset])
    if twin_frames == "prefix" and verbose:
        print(f"twin frames prefix: {sum(getattr(p, 'trimmed', 0) for p in parts)} items trimmed to their "
              "twins' common frames")
    if twin_frames == "overlap" and verbose:
        print(f"twin frames overlap: {sum(getattr(p, 'unequal', 0) for p in parts)} items paired with a twin of "
              "another length, over their common frames")
    if targets != "simulated" and verbose:  # one line per run, not per DDP rank
        anchored, simulated = sum(p.anchored for p in parts), sum(len(p.sim) for p in parts)
        print(f"{targets} targets: {anchored} of {simulated} simulated items (the rest keep the replay)")
    return dataset


def _provenance(args: argparse.Namespace, targets: str = "simulated", twin_frames: str = "equal",
                pair_twins: str = "all"):
    """What this run trains on (``model/provenance.json``); adapters add their backbone's record."""
    notes = [] if targets == "simulated" else [f"trained on {targets} targets"]
    if twin_frames != "equal":
        notes.append(f"twins of unequal length paired over their common frames (--twin-frames {twin_frames})")
    if pair_twins != "all":
        notes.append(f"per-frame paired loss on {pair_twins} twins only (--pair-twins {pair_twins})")
    from simdiff.model.provenance import Provenance, read_provenance, training_provenance, unknown_data

    init = getattr(args, "init", None)
    prov = training_provenance(args.mode, args.data or (), args.split, init=init, source=getattr(args, "source", None),
                               synthetic=args.synthetic, adapters_init=getattr(args, "adapters_init", None),
                               data_note="; ".join(notes))
    if args.mode == "adapters" and init is None:  # resuming: keep the backbone entries written before
        earlier = read_provenance(args.out / "model")
        backbone = [p for p in earlier.trained_on if p.what == "backbone"] if earlier is not None else []
        prov = Provenance((backbone or [unknown_data("backbone", args.out / "model", "resumed without --init")])
                          + prov.trained_on)
    return prov


def run(args: argparse.Namespace) -> int:
    import torch

    from simdiff.errors import SimdiffError
    from simdiff.inference.device import torch_device
    from simdiff.text.base import load_text_encoder
    from simdiff.train.distributed import init_from_env, shutdown
    from simdiff.train.state import latest_checkpoint
    from simdiff.train.trainer import Trainer

    config = _run_config(args)
    if args.no_resume and latest_checkpoint(args.out) is not None:
        raise SimdiffError(f"{args.out} already holds checkpoints (drop --no-resume to continue it)")
    device = torch_device(args.device)
    from simdiff.text.base import check_weights_option

    check_weights_option(args.clip_weights)
    dist = init_from_env(device)
    if device.type == "cuda" and dist.world_size > 1:
        device = torch.device("cuda", dist.local_rank)
    try:
        if args.text_table is not None:
            from simdiff.text.table import open_caption_table

            encoder = open_caption_table(args.text_table, config.model.text_encoder, device)
        else:
            encoder = load_text_encoder(config.model.text_encoder, device, args.clip_weights)
        dataset = _dataset(args, config.train.seed, config.train.targets, verbose=dist.is_main,
                           twin_frames=config.train.twin_frames)
        trainer = Trainer(args.out, config, dataset, text_encoder=encoder, device=device,
                          init_model=getattr(args, "init", None),
                          init_adapters=getattr(args, "adapters_init", None), rank=dist.rank,
                          world_size=dist.world_size,
                          provenance=_provenance(args, config.train.targets, config.train.twin_frames,
                                                 config.train.pair_twins),
                          loader_workers=args.loader_workers)
        losses = trainer.train_for(args.max_minutes, progress=not args.no_progress)
        if dist.is_main:
            tail = losses[-10:]
            final = f", final loss {sum(tail) / len(tail):.4f}" if tail else ""
            licence = trainer.provenance.weights_licence if trainer.provenance is not None else "unknown"
            print(f"trained {config.train.mode} to step {trainer.step}{final}; model: {args.out / 'model'} "
                  f"(weights licence: {licence})")
    finally:
        shutdown()
    return 0
