"""``simdiff data build-cmu`` and ``simdiff data report``: the CMU text–motion corpus."""

from __future__ import annotations

import argparse
from pathlib import Path

from simdiff.cli.main import command_group


def register(subparsers: argparse._SubParsersAction) -> None:
    group = command_group(subparsers, "data", "corpus tools")

    build = group.add_parser(
        "build-cmu",
        help="build a HumanML3D-layout corpus from CMU mocap (AMC/BVH/DeepMimic)",
        description=(
            "Retarget CMU trials to the 22-joint HumanML3D skeleton at 20 fps, cut 2-9.8 s clips "
            "(HumanML3D segment bounds where known), add mirrored M<id> copies, captions (KIT-ML "
            "where a trial has them, else sentences from CMU's description), splits by trial, "
            "Mean/Std and manifest.json. Incremental: re-running reuses finished trials."
        ),
    )
    build.add_argument("--src", type=Path, required=True, help="CMU source folder (e.g. ../shared/data/cmu)")
    build.add_argument("--out", type=Path, required=True, help="output corpus folder (keep it outside the repository)")
    build.add_argument("--seed", type=int, default=0, help="seed for captions and split order (default 0)")
    build.add_argument("--hml3d-splits", type=Path, default=None, metavar="DIR",
                       help="HumanML3D split files (default: SRC/../humanml3d/splits when present)")
    build.add_argument("--captions", type=int, default=3, metavar="N",
                       help="generated captions per clip without KIT-ML text (default 3)")
    build.add_argument("--no-mirror", action="store_true", help="do not write mirrored M<id> clips")
    build.add_argument("--sources", nargs="+", default=["amc", "bvh", "deepmimic"], metavar="KIND",
                       choices=["amc", "bvh", "deepmimic"],
                       help="source kinds a trial may come from, best present used (default: amc bvh deepmimic)")
    build.add_argument("--trials", nargs="+", default=None, metavar="SS_TT", help="only these trials")
    build.add_argument("--quiet", action="store_true", help="no progress bar")
    build.set_defaults(func=run_build)

    report = group.add_parser(
        "report",
        help="quality report of a built corpus (markdown + PNG)",
        description=(
            "Counts and hours per split, source and motion type; per-clip physics metrics; "
            "AMC vs BVH agreement of the trials captured in both; filmstrips. For a corpus of "
            "`simdiff data build`: hours by source/licence/motion type/split, flight time, physics "
            "metrics per source with outliers, dedupe cross-checks and a filmstrip per source."
        ),
    )
    report.add_argument("corpus", type=Path, help="corpus folder written by build-cmu or build")
    report.add_argument("--out", type=Path, default=None, help="report folder (default CORPUS/report)")
    report.add_argument("--src", type=Path, default=None, help="CMU source folder (default: the one in manifest.json)")
    report.add_argument("--seed", type=int, default=0, help="seed for the clips shown in filmstrips")
    report.add_argument("--no-crosscheck", action="store_true", help="skip the AMC/BVH comparison")
    report.set_defaults(func=run_report)


def run_build(args: argparse.Namespace) -> int:
    from simdiff.data.cmu.build import BuildConfig, build_corpus
    from simdiff.errors import SimdiffError

    if args.captions < 1:
        raise SimdiffError(f"--captions must be >= 1, got {args.captions}")
    cfg = BuildConfig(
        src=args.src, out=args.out, seed=args.seed, splits_dir=args.hml3d_splits,
        generated_captions=args.captions, mirror=not args.no_mirror, trials=args.trials,
        rigs=tuple(args.sources),
        progress=not args.quiet,
    )
    result = build_corpus(cfg)
    hours = sum(c["seconds"] for c in result.clips) / 3600
    splits = ", ".join(f"{k} {v}" for k, v in result.split_counts.items())
    print(f"{len(result.clips)} clips ({hours:.2f} h; {splits}) in {args.out}; "
          f"{result.processed} trial(s) processed, {result.reused} reused, {len(result.skipped)} skipped; "
          f"{result.elapsed:.1f} s")
    for item in result.skipped:
        print(f"  skipped {item['trial']}: {item['error']}")
    return 0


def run_report(args: argparse.Namespace) -> int:
    from simdiff.data.cmu.report import write_report
    from simdiff.data.corpus.build import FORMAT
    from simdiff.data.corpus.report import write_corpus_report
    from simdiff.data.report_blocks import load_manifest

    if load_manifest(args.corpus).get("format") == FORMAT:  # built by `simdiff data build`
        path = write_corpus_report(args.corpus, args.out, seed=args.seed, crosscheck=not args.no_crosscheck)
    else:
        path = write_report(args.corpus, args.out, src=args.src, seed=args.seed, crosscheck=not args.no_crosscheck)
    print(f"report written to {path}")
    return 0
