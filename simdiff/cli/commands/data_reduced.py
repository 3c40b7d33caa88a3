"""``simdiff data reduced-gravity``: low-gravity pairs of a corpus's jumps, walks and runs, made without the simulator."""

from __future__ import annotations

import argparse
from pathlib import Path

from simdiff.cli.main import command_group
from simdiff.cli.options import SEED, integer, real


def register(subparsers: argparse._SubParsersAction) -> None:
    group = command_group(subparsers, "data", "corpus tools")
    p = group.add_parser(
        "reduced-gravity",
        help="low-gravity pairs of jumps (ballistic flights) and walks/runs (Froude-slowed), without the simulator",
        description=(
            "For every clip of --split whose motion_type is jump, walk or run: an Earth item and --conditions items "
            "under g_z drawn uniformly in --gravity-range. Jumps keep their take-off and fly ballistically under g "
            "(apex and flight time grow by about 9.81/|g|); walks and runs are slowed by sqrt(9.81/|g|), the "
            "dynamically similar gait. Writes the layout of `simdiff data augment` (env.json, train.txt, ...), for "
            "`simdiff train adapters --data` (simdiff.data.augment.kinematic)."
        ),
    )
    p.add_argument("--corpus", type=Path, required=True, help="a corpus folder of `simdiff data build`")
    p.add_argument("--out", type=Path, required=True, help="output folder (new or one this command wrote)")
    p.add_argument("--split", default="train", help="split file of the corpus (default train)")
    p.add_argument("--conditions", type=integer(1, 64), default=4,
                   help="reduced-gravity items per clip besides its Earth item (default 4)")
    p.add_argument("--gravity-range", nargs=2, type=real(-9.81, -1.0), metavar=("LO", "HI"),
                   default=(-5.0, -1.0), help="draw g_z uniformly in [LO, HI] m/s^2, -9.81 <= LO < HI <= -1 (default -5 -1)")
    p.add_argument("--seed", type=SEED, default=0, help="seed of the gravity draws (default 0)")
    p.add_argument("--no-progress", action="store_true", help="hide the progress bar")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from simdiff.data.augment.kinematic import KinematicConfig, make_reduced_gravity

    config = KinematicConfig(args.split, args.conditions, tuple(args.gravity_range), args.seed)
    s = make_reduced_gravity(args.corpus, args.out, config, progress=not args.no_progress)
    print(f"{s['items']} items from {s['sources']} clips ({s['skipped']} skipped: not a free flight or over "
          f"30 s) written to {args.out}")
    return 0
