"""``simdiff data augment``: replay a corpus's training clips in the simulator under φ and keep the good rollouts."""

from __future__ import annotations

import argparse
from pathlib import Path

from simdiff.cli.main import command_group


def register(subparsers: argparse._SubParsersAction) -> None:
    group = command_group(subparsers, "data", "build and augment corpora")
    p = group.add_parser(
        "augment", help="simulator-augmented corpus: project training clips under gravity/wind, filter, write + φ",
        description="Project every training clip through the MuJoCo tracker under Earth gravity (binary) or 30 "
                    "random one-factor environments (random), keep pairs that tracked to the end with d_L2 <= 7 and "
                    "a small root residual, and write them in the HumanML3D layout with env.json. Sharded and "
                    "resumable: run the same command again after an interruption.")
    p.add_argument("--corpus", type=Path, required=True, help="source corpus (HumanML3D layout with Mean.npy/Std.npy)")
    p.add_argument("--out", type=Path, required=True, help="output folder (resumed if it exists)")
    p.add_argument("--mode", choices=["binary", "random"], default="random", help="binary: Earth only; random: --conditions environments (default)")
    p.add_argument("--conditions", type=int, default=30, help="random environments (default 30)")
    p.add_argument("--split", default="train", help="source split to augment (default train)")
    p.add_argument("--workers", type=int, default=0, help="parallel simulations (default: all cores)")
    p.add_argument("--backend", choices=["process", "ray", "serial"], default="process", help="parallel backend (default process)")
    p.add_argument("--seed", type=int, default=0, help="seed of the environment draw (default 0)")
    p.add_argument("--max-d-l2", type=float, default=7.0, help="largest d_L2 kept (default 7.0, the paper's)")
    p.add_argument("--max-residual", type=float, default=0.1,
                   help="largest mean root residual force kept, fraction of m*|g_z| (default 0.1)")
    p.add_argument("--residual-bound", type=float, default=0.5,
                   help="tracker's root residual bound, fraction of m*|g_z| (default 0.5; 0 = strict, no residual)")
    p.add_argument("--shard-size", type=int, default=4, help="source clips per shard (default 4)")
    p.add_argument("--per-clip", type=int,
                   help="random mode: project each clip under this many of the conditions, balanced "
                        "round-robin (default: all of them; the paper's full cross product)")
    p.add_argument("--limit", type=int, help="augment only the first N clips of the split")
    p.add_argument("--no-progress", action="store_true", help="hide the progress bar")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from simdiff.data.augment.filter import FilterConfig
    from simdiff.data.augment.run import AugmentConfig, augment

    config = AugmentConfig(mode=args.mode, conditions=args.conditions, seed=args.seed, split=args.split,
                           shard_size=args.shard_size, limit=args.limit,
                           filter=FilterConfig(max_d_l2=args.max_d_l2, max_residual=args.max_residual),
                           residual_bound=args.residual_bound, workers=args.workers, backend=args.backend,
                           per_clip=args.per_clip)
    report = augment(args.corpus, args.out, config, progress=not args.no_progress)
    frac = report["kept_fraction"]
    print(f"kept {report['kept']}/{report['pairs']} pairs" + (f" ({100 * frac:.1f} %)" if frac is not None else "")
          + f" from {report['clips']} clips; corpus: {args.out} (report: {args.out / 'report.md'})")
    return 0
