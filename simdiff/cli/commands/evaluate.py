"""``simdiff evaluate train-evaluator|run|all``: our T2M-style evaluator and the paper's experiments."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from simdiff.cli.options import MAX_TRAIN_BATCH, SEED, integer, real
from simdiff.cli.main import command_group


def register(subparsers: argparse._SubParsersAction) -> None:
    group = command_group(subparsers, "evaluate", "text-to-motion evaluation: evaluator training, tables and figures")
    t = group.add_parser("train-evaluator", help="train our text-motion contrastive evaluator on a corpus's train split",
                         description="Train the movement-encoder + BiGRU motion encoder and MiniLM text projection with "
                                     "Guo et al.'s contrastive loss on the train split (best epoch on val). Resumable.")
    t.add_argument("--corpus", type=Path, required=True, help="HumanML3D-layout corpus")
    t.add_argument("--out", type=Path, required=True, help="output folder (model.safetensors + config.json, checkpoint/)")
    t.add_argument("--epochs", type=integer(1, 10_000), default=30, help="passes over the train split (default 30)")
    t.add_argument("--batch-size", type=integer(2, MAX_TRAIN_BATCH), default=32, help="pairs per step (default 32)")
    t.add_argument("--lr", type=real(0.0, 1.0, above=True), default=1e-3, help="Adam learning rate (default 1e-3)")
    t.add_argument("--embed-dim", type=integer(8, 4096), default=256, help="shared embedding size (default 256; T2M 512)")
    t.add_argument("--seed", type=SEED, default=0, help="seed (default 0)")
    t.add_argument("--device", default="cpu", help="torch device (default cpu)")
    t.add_argument("--no-progress", action="store_true", help="hide the progress bar")
    t.set_defaults(func=run_train)
    r = group.add_parser("run", help="run one experiment config (configs/eval_*.json) into reports/<name>/",
                         description="Measure table1, table2, fig4, fig5, retrack, env_response, contacts, editing, following or heldout from a JSON config into "
                                     "<out-dir>/<name>/ (report.md, report.json, figures). Finished rows are cached, so an "
                                     "interrupted run resumes; a row whose settings changed is measured again.")
    r.add_argument("config", type=Path, help="experiment config (configs/eval_<kind>.json)")
    _common(r)
    r.set_defaults(func=run_experiment)
    a = group.add_parser("all", help="run table2, table1, fig4, fig5, retrack, env_response, contacts, editing, following and heldout in sequence",
                         description="Run every experiment in order (table2 first: table1 takes its best α and reuses "
                                     "its rows) from <configs>/eval_<kind>.json. --budget quick is the ~30-minute CPU "
                                     "preset each config defines; full is the configs as written.")
    a.add_argument("--configs", type=Path, default=Path("configs"), help="folder with eval_<kind>.json (default configs)")
    a.add_argument("--only", nargs="+", metavar="KIND", help="run only these experiments (table1 table2 fig4 fig5 retrack env_response contacts editing following heldout)")
    _common(a)
    a.set_defaults(func=run_all)


def _common(p: argparse.ArgumentParser) -> None:
    """Budget, path overrides, --set, output, device, dry run, progress."""
    p.add_argument("--budget", choices=("quick", "full"), default="full",
                   help="CPU budget preset from the config's 'budgets' (default full: the config as written)")
    p.add_argument("--corpus", help="HumanML3D-layout corpus folder (overrides 'corpus')")
    p.add_argument("--evaluator", help="evaluator folder (overrides 'evaluator.path')")
    p.add_argument("--backbone", help="MDM backbone model folder (overrides 'paths.backbone'); a SimDiff model folder gives its frozen backbone alone")
    p.add_argument("--adapters", help="continuous (φ) SimDiff model folder (overrides 'paths.adapters')")
    p.add_argument("--adapters-binary", help="categorical (binary) SimDiff model folder (overrides 'paths.adapters_binary')")
    p.add_argument("--set", dest="assignments", action="append", default=[], metavar="KEY=VALUE",
                   help="override any config value by dotted key, e.g. protocol.replications=3 or models.0.alpha=0.5 "
                        "(VALUE is JSON when it parses); repeatable")
    p.add_argument("--out-dir", help="reports folder (overrides 'out_dir', default reports)")
    p.add_argument("--device", help="torch device (overrides 'device', default cpu)")
    p.add_argument("--dry-run", action="store_true", help="list the rows (cached / reused / to measure) with time estimates")
    p.add_argument("--no-progress", action="store_true", help="hide progress bars")


def _overrides(args: argparse.Namespace) -> list[tuple[str, object]]:
    from simdiff.eval.experiments.config import parse_assignment

    out: list[tuple[str, object]] = [parse_assignment(a) for a in args.assignments]
    for flag, key in (("corpus", "corpus"), ("evaluator", "evaluator.path"), ("backbone", "paths.backbone"),
                      ("adapters", "paths.adapters"), ("adapters_binary", "paths.adapters_binary"),
                      ("out_dir", "out_dir"), ("device", "device")):
        if getattr(args, flag) is not None:
            out.append((key, getattr(args, flag)))
    return out


def run_train(args: argparse.Namespace) -> int:
    import json

    from simdiff.errors import SimdiffError
    from simdiff.eval.evaluator import EvaluatorConfig
    from simdiff.eval.train_evaluator import EvaluatorTrainConfig, train_evaluator

    from simdiff.inference.device import torch_device

    device = torch_device(args.device)
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
    summary = train_evaluator(args.corpus, args.out, config, device=device, progress=not args.no_progress)
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


def _print_plan(rows: list[dict]) -> float:
    from simdiff.eval.experiments.report import duration

    for r in rows:
        print(f"  {r['experiment']:8s} {r['key']:40s} {r['state']:8s} {duration(r['estimate_s']) if r['estimate_s'] else ''}")
    total = sum(r["estimate_s"] for r in rows)
    print(f"  {rows[0]['experiment'] if rows else ''}: {len(rows)} rows, estimated {duration(total)} to measure")
    return total


def run_experiment(args: argparse.Namespace) -> int:
    from simdiff.eval.experiments import plan_experiment, run_experiment as run

    overrides = _overrides(args)
    if args.dry_run:
        _print_plan(plan_experiment(args.config, budget=args.budget, overrides=overrides))
        return 0
    report = run(args.config, budget=args.budget, overrides=overrides, command=["simdiff", *sys.argv[1:]],
                 progress=not args.no_progress)
    out = Path(report["config"]["out_dir"]) / report["name"]
    print(f"{report['kind']} {report['name']}: {len(report['rows'])} rows; report: {out / 'report.md'}")
    return 0


def run_all(args: argparse.Namespace) -> int:
    from simdiff.eval.experiments import ORDER, config_path, plan_experiment, run_all as run
    from simdiff.eval.experiments.report import duration

    unknown = [k for k in args.only or [] if k not in ORDER]
    if unknown:
        from simdiff.errors import SimdiffError

        raise SimdiffError(f"--only {unknown[0]}: unknown experiment; choose from {' '.join(ORDER)}")
    overrides = _overrides(args)
    if args.dry_run:
        total = 0.0
        for kind in [k for k in ORDER if not args.only or k in args.only]:
            total += _print_plan(plan_experiment(config_path(args.configs, kind), budget=args.budget, overrides=overrides))
        print(f"all: estimated {duration(total)} (table1's best-α rows and the rows it reuses from table2 "
              "are known only once table2 has run)")
        return 0
    run(args.configs, budget=args.budget, overrides=overrides, only=args.only, command=["simdiff", *sys.argv[1:]],
        progress=not args.no_progress)
    return 0
