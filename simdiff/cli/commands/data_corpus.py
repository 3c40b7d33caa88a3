"""``simdiff data build`` (one corpus from every motion source under ``../shared/data``) and ``simdiff data report``."""

from __future__ import annotations

import argparse
from pathlib import Path

from simdiff.cli.main import command_group
from simdiff.cli.options import SEED, WORKERS, integer

MIN_CAPTIONS, MAX_CAPTIONS = 2, 10
"""--captions range (as :data:`simdiff.data.corpus.build.MAX_CAPTIONS`)."""


def register(subparsers: argparse._SubParsersAction) -> None:
    from simdiff.licences import LICENCE_SETS
    from simdiff.data.corpus.registry import SOURCES

    group = command_group(subparsers, "data", "corpus tools")
    build = group.add_parser(
        "build",
        help="build one HumanML3D-layout corpus from every motion source (CMU, Bandai, HDM05, DeepMimic)",
        description=(
            "Discover every source under --shared (CMU AMC/BVH/DeepMimic, extra CMU BVH, Bandai-Namco, "
            "HDM05, DeepMimic clips), keep one copy of each capture (AMC first; the others are "
            "cross-checks), retarget to 22 joints at 20 fps, cut 2-9.8 s clips, add M<id> mirrors, "
            "captions (>= 2 per clip), licence per clip, splits by trial stratified by source and motion "
            "type, Mean/Std and manifest.json. Resumable; output independent of --workers. "
            "`--sources cmu` builds the CMU trials alone."
        ),
    )
    build.add_argument("--shared", type=Path, required=True, help="shared data root (e.g. ../shared/data)")
    build.add_argument("--out", type=Path, required=True, help="output corpus folder (keep it outside the repository)")
    build.add_argument("--licence", choices=sorted(LICENCE_SETS), default="all",
                       help="all (default, research use) or permissive (no CC BY-NC, no CC BY-SA)")
    build.add_argument("--sources", nargs="+", choices=list(SOURCES), default=list(SOURCES), metavar="SOURCE",
                       help=f"source families (default all: {' '.join(SOURCES)})")
    build.add_argument("--workers", type=WORKERS, default=2,
                       help="worker processes, 0..64 (0: one per CPU core; default 2)")
    build.add_argument("--seed", type=SEED, default=0, help="seed for captions and split order, 0..2^32-1 (default 0)")
    build.add_argument("--captions", type=integer(MIN_CAPTIONS, MAX_CAPTIONS), default=3, metavar="N",
                       help=f"generated captions per clip, {MIN_CAPTIONS}..{MAX_CAPTIONS} (default 3)")
    build.add_argument("--no-mirror", action="store_true", help="do not write mirrored M<id> clips")
    build.add_argument("--quiet", action="store_true", help="no progress bar")
    build.set_defaults(func=run_build)

    report = group.add_parser(
        "report",
        help="quality report of a built corpus (markdown + PNG)",
        description=(
            "Hours by source, licence, motion type and split; flight time; physics metrics per source with "
            "outliers; dedupe cross-checks (kept copy vs the other copies of a capture); a filmstrip per source."
        ),
    )
    report.add_argument("corpus", type=Path, help="corpus folder written by `simdiff data build`")
    report.add_argument("--out", type=Path, default=None, help="report folder (default CORPUS/report)")
    report.add_argument("--seed", type=SEED, default=0, help="seed for the clips shown in filmstrips, 0..2^32-1")
    report.add_argument("--no-crosscheck", action="store_true", help="skip the comparison of copies")
    report.set_defaults(func=run_report)


def run_build(args: argparse.Namespace) -> int:
    from simdiff.data.corpus.build import CorpusConfig, build
    from simdiff.sim.pool import WorkerDied, stop_signals, stopped

    cfg = CorpusConfig(shared=args.shared, out=args.out, licence=args.licence, sources=tuple(args.sources),
                       workers=args.workers, seed=args.seed, captions=args.captions, mirror=not args.no_mirror,
                       progress=not args.quiet)
    try:
        with stop_signals():  # SIGTERM as Ctrl-C: workers stopped, finished items kept for the rerun
            result = build(cfg)
    except (KeyboardInterrupt, WorkerDied) as exc:
        return stopped(exc)
    originals = [c for c in result.clips if c["mirror_of"] is None]
    hours = sum(c["seconds"] for c in result.clips) / 3600
    hours0 = sum(c["seconds"] for c in originals) / 3600
    splits = ", ".join(f"{k} {v}" for k, v in result.split_counts.items())
    print(f"{len(result.clips)} clips ({hours0:.2f} h original, {hours:.2f} h with mirrors; {splits}) in {args.out}; "
          f"{result.processed} item(s) processed, {result.reused} reused, {len(result.skipped)} skipped; "
          f"{result.elapsed:.1f} s")
    by_licence: dict[str, float] = {}
    for clip in originals:
        by_licence[clip["licence"]] = by_licence.get(clip["licence"], 0.0) + clip["seconds"] / 3600
    print("hours (original) by licence: " + ", ".join(f"{k} {v:.2f}" for k, v in sorted(by_licence.items())))
    reasons: dict[str, int] = {}
    for item in result.skipped:
        reason = "shorter than 2 s" if "shorter than" in item["error"] else item["error"].split(": ", 1)[-1][:80]
        reasons[reason] = reasons.get(reason, 0) + 1
    for reason, count in sorted(reasons.items(), key=lambda kv: -kv[1])[:10]:
        print(f"  skipped {count}: {reason}")
    return 0


def run_report(args: argparse.Namespace) -> int:
    from simdiff.data.corpus.report import write_corpus_report
    from simdiff.viz.stick import render_filmstrip

    path = write_corpus_report(args.corpus, args.out, render_filmstrip=render_filmstrip, seed=args.seed,
                               crosscheck=not args.no_crosscheck)
    print(f"report written to {path}")
    return 0
