"""The augmentation report of an existing run folder, read-only (also while the run is still going).

Usage:
    python benchmarks/augment_report.py --run /path/to/augment_out --corpus /path/to/corpus \
        --md reports/augment/run_report.md --json reports/augment/run_report.json

Reads the run's ``augment_settings.json`` and its finished shards, applies the filter
(:func:`simdiff.data.augment.decide.decide`; default ``--max-pose-d-l2 auto``) and writes the
report (:mod:`simdiff.data.augment.report`: per bin, per bin × content class, the Earth-tracked
view, the "done when" checklist) to the given files. Nothing in the run folder is written: unlike
re-running ``simdiff data augment`` with the same arguments, no split, env.json or file clean-up.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from simdiff.data.augment import AugmentConfig, FilterConfig
from simdiff.data.augment.classes import load_motion_types
from simdiff.data.augment.conditions import make_conditions
from simdiff.data.augment.decide import decide
from simdiff.data.augment.report import build_report, report_markdown
from simdiff.errors import SimdiffError
from simdiff.fsio import write_text


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--run", type=Path, required=True, help="output folder of `simdiff data augment`")
    ap.add_argument("--corpus", type=Path, required=True, help="its source corpus (manifest.json for the classes)")
    ap.add_argument("--max-pose-d-l2", default="auto", help="number or 'auto' (default)")
    ap.add_argument("--earth-keep", type=float, default=0.66)
    ap.add_argument("--max-residual-n", type=float, default=FilterConfig().max_residual_n)
    ap.add_argument("--md", type=Path, required=True)
    ap.add_argument("--json", type=Path)
    args = ap.parse_args()
    try:
        settings = json.loads((args.run / "augment_settings.json").read_text(encoding="utf-8"))
        pose = args.max_pose_d_l2 if args.max_pose_d_l2 == "auto" else float(args.max_pose_d_l2)
        filt = FilterConfig(max_pose_d_l2=pose, earth_keep=args.earth_keep, max_residual_n=args.max_residual_n)
        config = AugmentConfig(mode=settings["mode"], conditions=settings["conditions"], seed=settings["seed"],
                               split=settings["split"], shard_size=settings["shard_size"],
                               residual_bound=settings["residual_bound"], per_clip=settings.get("per_clip"),
                               share_mirrors=bool(settings.get("share_mirrors")), filter=filt)
        records = [r for p in sorted((args.run / "shards").glob("shard_*.json"))
                   for r in json.loads(p.read_text(encoding="utf-8"))["records"]]
        decided, summary = decide(records, filt)
        report = build_report(decided, make_conditions(config.mode, config.n_conditions, config.seed), config, summary,
                              motion_types=load_motion_types(args.corpus))
    except (OSError, ValueError, KeyError) as exc:
        print(f"error: {args.run}: {exc}", file=sys.stderr)
        return 2
    except SimdiffError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    write_text(args.md, report_markdown(report))
    if args.json is not None:
        write_text(args.json, json.dumps(report, indent=1) + "\n")
    verdict = report["checklist"]["passes"]
    print(f"{report['pairs']} pairs from {report['clips']} clips; done-when: {'PASS' if verdict else 'FAIL'}; {args.md}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
