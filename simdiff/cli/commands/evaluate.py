"""``simdiff evaluate train-evaluator|run``: our T2M-style evaluator and the experiment runner."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from simdiff.cli.main import command_group


def register(subparsers: argparse._SubParsersAction) -> None:
    group = command_group(subparsers, "evaluate", "text-to-motion evaluation: evaluator training, tables and figures")
    t = group.add_parser("train-evaluator", help="train our text-motion contrastive evaluator on a corpus's train split",
                         description="Train the movement-encoder + BiGRU motion encoder and MiniLM text projection with "
                                     "Guo et al.'s contrastive loss on the train split (best epoch on val). Resumable.")
    t.add_argument("--corpus", type=Path, required=True, help="HumanML3D-layout corpus")
    t.add_argument("--out", type=Path, required=True, help="output folder (model.safetensors + config.json, checkpoint/)")
    t.add_argument("--epochs", type=int, default=30, help="passes over the train split (default 30)")
    t.add_argument("--batch-size", type=int, default=32, help="pairs per step (default 32)")
    t.add_argument("--lr", type=float, default=1e-3, help="Adam learning rate (default 1e-3)")
    t.add_argument("--embed-dim", type=int, default=256, help="shared embedding size (default 256; T2M 512)")
    t.add_argument("--seed", type=int, default=0, help="seed (default 0)")
    t.add_argument("--device", default="cpu", help="torch device (default cpu)")
    t.add_argument("--no-progress", action="store_true", help="hide the progress bar")
    t.set_defaults(func=run_train)
    r = group.add_parser("run", help="run an experiment config (configs/eval_*.json) into reports/",
                         description="Measure a table or figure (table1, table2, fig4, fig5, retrack) from a JSON config; "
                                     "finished rows are cached, so an interrupted run resumes.")
    r.add_argument("--config", type=Path, required=True, help="experiment config (configs/eval_*.json)")
    r.add_argument("--out-dir", help="reports folder (default: the config's out_dir, 'reports')")
    r.add_argument("--device", help="torch device (default: the config's)")
    r.add_argument("--no-progress", action="store_true", help="hide progress bars")
    r.set_defaults(func=run_experiment)


def run_train(args: argparse.Namespace) -> int:
    import json

    from simdiff.errors import SimdiffError
    from simdiff.eval.evaluator import EvaluatorConfig
    from simdiff.eval.train_evaluator import EvaluatorTrainConfig, train_evaluator

    state = args.out / "checkpoint" / "state.json"
    config = EvaluatorTrainConfig(evaluator=EvaluatorConfig(embed_dim=args.embed_dim), epochs=args.epochs,
                                  batch_size=args.batch_size, lr=args.lr, seed=args.seed)
    if state.is_file():  # continuing: allow more epochs, nothing else
        saved = json.loads(state.read_text())["config"]
        if {k: v for k, v in saved.items() if k != "epochs"} != {k: v for k, v in _asdict(config).items() if k != "epochs"}:
            raise SimdiffError(f"{args.out} holds a run with different options; use a new --out")
        saved["epochs"] = args.epochs
        data = json.loads(state.read_text())
        data["config"] = saved
        from simdiff.model.checkpoint import atomic_write_json

        atomic_write_json(data, state)
    summary = train_evaluator(args.corpus, args.out, config, device=args.device, progress=not args.no_progress)
    last = summary["history"][-1] if summary["history"] else {}
    val = last.get("val")
    tail = f", val top-1 {val['top1']:.3f} top-3 {val['top3']:.3f}" if val else ""
    print(f"evaluator trained to epoch {len(summary['history'])} (loss {last.get('loss', float('nan')):.3f}{tail}); "
          f"weights: {args.out / 'model.safetensors'}")
    return 0


def _asdict(config) -> dict:
    import dataclasses
    import json

    return json.loads(json.dumps(dataclasses.asdict(config)))


def run_experiment(args: argparse.Namespace) -> int:
    from simdiff.eval.experiments import run_experiment as run

    report = run(args.config, command=["simdiff", *sys.argv[1:]], progress=not args.no_progress,
                 out_dir=args.out_dir, device=args.device)
    out = Path(report["config"]["out_dir"]) / report["name"]
    print(f"{report['kind']} {report['name']}: {len(report['rows'])} rows; report: {out / 'report.md'}")
    return 0
