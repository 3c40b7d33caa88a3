"""``simdiff train pipeline`` (every stage, resumable, skips current stages) and ``train pack`` / ``unpack``."""

from __future__ import annotations

import argparse
from pathlib import Path

from simdiff.cli.options import SEED, WORKERS, real
from simdiff.cli.main import command_group


def register(subparsers: argparse._SubParsersAction) -> None:
    group = command_group(subparsers, "train", "train the diffusion backbone or SimDiff's adapters")
    p = group.add_parser("pipeline", help="corpus → augmentation → backbone → adapters → evaluator → evaluation → export",
                         description="Run every stale stage of the training pipeline into --out. Each stage leaves "
                                     "stages/<name>.json (hash of its settings and inputs) and is skipped when current; "
                                     "interrupted stages resume.")
    p.add_argument("--budget", choices=["quick", "cpu", "gpu"], default="cpu", help="settings preset (default cpu)")
    p.add_argument("--out", type=Path, required=True, help="run folder")
    p.add_argument("--corpus", help="HumanML3D-layout corpus or pack folder (else --shared builds one)")
    p.add_argument("--shared", help="shared data root to build the corpus from")
    p.add_argument("--augmented", help="an existing augmented corpus or pack (skips the simulation)")
    p.add_argument("--text-table", type=Path,
                   help="precomputed caption embeddings (`simdiff train text-table`) instead of loading the text "
                        "encoder's weights (a GPU machine without them)")
    p.add_argument("--config", type=Path, help="a pipeline config JSON (as written to <out>/pipeline_config.json)")
    p.add_argument("--set", action="append", default=[], metavar="SECTION.KEY=VALUE",
                   help="override a setting, e.g. backbone.steps=500 (repeatable)")
    p.add_argument("--seed", type=SEED, help="seed of every stage (default 10)")
    p.add_argument("--sim-workers", type=WORKERS, help="simulation processes (0 = all cores)")
    p.add_argument("--device", default="cpu", help="torch device for training and evaluation (cpu, cuda)")
    p.add_argument("--dry-run", action="store_true", help="print the plan (stage, current/resume/run, key) and stop")
    p.add_argument("--no-progress", action="store_true", help="hide progress bars")
    p.set_defaults(func=run_pipeline_cmd)

    k = group.add_parser("pack", help="write a corpus as compact arrays (for carrying to a GPU machine)")
    k.add_argument("corpus", type=Path, help="HumanML3D-layout corpus folder")
    k.add_argument("--out", type=Path, required=True, help="pack folder")
    k.add_argument("--workers", type=WORKERS, default=1, help="processes encoding clips (0: all cores)")
    k.add_argument("--no-progress", action="store_true", help="hide the progress bar")
    k.add_argument("--splits", nargs="+", help="pack only these split files' clips (default all)")
    k.add_argument("--budget-mib", type=real(0.0, 1e6), default=64.0, help="refuse a pack larger than this (0: no check)")
    k.set_defaults(func=run_pack)

    t = group.add_parser("text-table", help="encode every caption of corpora once (for a machine without the "
                                            "text encoder's weights: `train pipeline --text-table`)")
    t.add_argument("corpus", type=Path, nargs="+", help="HumanML3D-layout corpus folders (texts/*.txt, all splits)")
    t.add_argument("--out", type=Path, required=True, help="table file to write (.safetensors)")
    t.add_argument("--captions", type=Path, help="a text file of further captions, one per line (e.g. prompts)")
    t.add_argument("--encoder", default="minilm", help="text encoder (default minilm)")
    t.add_argument("--dtype", choices=["float16", "float32"], default="float16",
                   help="stored precision (float16: half the size, within about 1e-3)")
    t.set_defaults(func=run_text_table)

    c = group.add_parser("coverage", help="write a model folder's table of training captions (generate warns on "
                                          "prompts far from all of them)",
                         description="Encode the distinct captions of CORPUS's --split with the model's text encoder "
                                     "and write MODEL/captions.safetensors (float16); `simdiff generate` then warns when "
                                     "a prompt is far from every one of them. The pipeline's export writes it itself.")
    c.add_argument("corpus", type=Path, help="the HumanML3D-layout corpus the model trained on")
    c.add_argument("--model", type=Path, required=True, help="model folder (model.safetensors + config.json)")
    c.add_argument("--split", default="train", help="the split the model trained on (default: train)")
    c.set_defaults(func=run_coverage)

    u = group.add_parser("unpack", help="restore a pack as a HumanML3D-layout corpus folder")
    u.add_argument("pack", type=Path, help="pack folder")
    u.add_argument("--out", type=Path, required=True, help="corpus folder to write")
    u.add_argument("--workers", type=WORKERS, default=0, help="processes rebuilding features (0: all cores)")
    u.add_argument("--no-progress", action="store_true", help="hide the progress bar")
    u.set_defaults(func=run_unpack)


def _config(args: argparse.Namespace):
    import json

    from simdiff.errors import SimdiffError
    from simdiff.model.config import config_from_dict
    from simdiff.train.pipeline.config import PipelineConfig, budget_config, set_option

    if args.config is not None:
        try:
            data = json.loads(args.config.read_text(encoding="utf-8"))
        except json.JSONDecodeError as exc:
            raise SimdiffError(f"{args.config}: invalid JSON ({exc.msg}, line {exc.lineno})") from None
        except (OSError, UnicodeDecodeError) as exc:
            raise SimdiffError(f"{args.config}: cannot read pipeline config ({type(exc).__name__})") from None
        config = config_from_dict(data, PipelineConfig, str(args.config))
    else:
        config = budget_config(args.budget)
    for flag, setting in (("corpus", "corpus.path"), ("shared", "corpus.shared"), ("augmented", "augment.path"),
                          ("text_table", "text_table")):
        if getattr(args, flag):
            set_option(config, f"{setting}={json.dumps(str(getattr(args, flag)))}")
    if args.seed is not None:
        config.seed = args.seed
    if args.sim_workers is not None:
        config.augment.workers = config.corpus.workers = args.sim_workers
    for assignment in args.set:
        set_option(config, assignment)
    if isinstance(config.evaluation.env, list):
        config.evaluation.env = tuple(config.evaluation.env)
    return config


def run_pipeline_cmd(args: argparse.Namespace) -> int:
    from simdiff.inference.device import torch_device
    from simdiff.train.pipeline import run_pipeline

    device = torch_device(args.device)
    run_pipeline(_config(args), args.out, device=device, dry_run=args.dry_run, progress=not args.no_progress)
    return 0


def run_pack(args: argparse.Namespace) -> int:
    from simdiff.cli.paths import check_separate
    from simdiff.data.pack import pack

    check_separate(args.out, CORPUS=args.corpus)
    info = pack(args.corpus, args.out, budget_mib=args.budget_mib, splits=args.splits, workers=args.workers,
                progress=not args.no_progress)
    print(f"packed {info['clips']} clips ({info.get('mirrors', 0)} as mirrors), {info['frames']} frames "
          f"({info['dtype']}): "
          f"{info['bytes'] / 2**20:.2f} MiB in {args.out}")
    return 0


def run_unpack(args: argparse.Namespace) -> int:
    from simdiff.cli.paths import check_separate
    from simdiff.data.pack import unpack

    check_separate(args.out, PACK=args.pack)
    n = unpack(args.pack, args.out, workers=args.workers, progress=not args.no_progress)
    print(f"unpacked {n} clips into {args.out}")
    return 0


def run_text_table(args: argparse.Namespace) -> int:
    from simdiff.errors import SimdiffError
    from simdiff.text.base import load_text_encoder
    from simdiff.data.humanml3d import corpus_captions
    from simdiff.text.table import write_caption_table

    captions: list[str] = []
    for corpus in args.corpus:
        captions += corpus_captions(corpus)
    if args.captions is not None:
        try:
            captions += [line.strip() for line in args.captions.read_text(encoding="utf-8").splitlines() if line.strip()]
        except OSError as exc:
            raise SimdiffError(f"--captions {args.captions}: cannot read ({exc.strerror or type(exc).__name__})") from None
        except UnicodeDecodeError:
            raise SimdiffError(f"--captions {args.captions}: not a UTF-8 text file of captions, one per line") from None
    info = write_caption_table(captions, load_text_encoder(args.encoder), args.out, dtype=args.dtype)
    print(f"wrote {info['captions']} captions × {info['dim']} ({info['dtype']}): "
          f"{int(info['bytes']) / 2**20:.2f} MiB in {args.out}")
    return 0


def run_coverage(args: argparse.Namespace) -> int:
    from simdiff.inference import coverage
    from simdiff.inference.default import check_model_dir
    from simdiff.model.checkpoint import read_config
    from simdiff.text.base import load_text_encoder

    folder = check_model_dir(args.model)
    captions = coverage.training_captions(args.corpus, args.split)
    info = coverage.write_coverage_table(folder, captions, load_text_encoder(read_config(folder).text_encoder))
    print(f"wrote {info['captions']} captions × {info['dim']} (float16): {int(info['bytes']) / 2**20:.2f} MiB in "
          f"{folder / coverage.COVERAGE_NAME}")
    return 0
