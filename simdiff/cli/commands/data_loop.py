"""``simdiff data loop``: short cyclic walks/runs of a corpus repeated to a longer length (extra train clips)."""

from __future__ import annotations

import argparse
from pathlib import Path

from simdiff.cli.options import integer, real
from simdiff.motion.skeleton import MAX_FRAMES, MIN_GENERATE_FRAMES
from simdiff.cli.main import command_group


def register(subparsers: argparse._SubParsersAction) -> None:
    from simdiff.data.loop import MAX_ERROR

    group = command_group(subparsers, "data", "corpus tools")
    loop = group.add_parser(
        "loop",
        help="repeat a corpus's short cyclic walks/runs to a longer length, as extra train clips",
        description=(
            "For every clip of --split whose motion_type is in --types, shorter than --frames and not padded: find "
            "its period (the lag whose pose best repeats its first frames), repeat it to --frames feature rows "
            "(20 fps) moving each copy as the body moved over one period, and write it as L<id> with the clip's "
            "captions. Writes <out-split>.txt (the split's ids plus the loops) and loops.json; manifest.json, the "
            "split files and Mean/Std stay as they are. Train on the new split with `simdiff train backbone "
            "--split <out-split>`."
        ),
    )
    loop.add_argument("corpus", type=Path, help="a corpus folder of `simdiff data build`")
    loop.add_argument("--types", nargs="+", default=["run"], metavar="TYPE",
                      help="motion types to loop (default: run)")
    loop.add_argument("--frames", type=integer(MIN_GENERATE_FRAMES, MAX_FRAMES), default=120, help="length of each loop in frames at 20 fps (default 120)")
    loop.add_argument("--split", default="train", help="split whose clips are looped (default train)")
    loop.add_argument("--out-split", default="", help="name of the new split file (default <split>_loop)")
    loop.add_argument("--max-error", type=real(0.0, 10.0, above=True), default=MAX_ERROR,
                      help=f"largest period mismatch kept, mean joint distance in metres (default {MAX_ERROR})")
    loop.add_argument("--quiet", action="store_true", help="no progress bar")
    loop.set_defaults(func=run_loop)


def run_loop(args: argparse.Namespace) -> int:
    from simdiff.data.loop import loop_corpus

    result = loop_corpus(args.corpus, args.types, args.frames, args.split, args.out_split, args.max_error,
                         progress=not args.quiet)
    periods = sorted(r["period"] for r in result.looped)
    median = periods[len(periods) // 2] if periods else 0
    print(f"{len(result.looped)} loops of {args.frames} frames written to {args.corpus} (median period {median} "
          f"frames), {len(result.skipped)} clip(s) skipped; split file {result.split_file}")
    return 0
