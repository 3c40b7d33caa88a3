"""``simdiff metrics FILE...``: physics metrics (penetration, floating, sliding, skate ratio, floor contact)."""

from __future__ import annotations

import argparse
import json
from pathlib import Path


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser(
        "metrics",
        help="physics metrics of motion files (penetration, floating, sliding in mm; skate ratio)",
        description=(
            "Physics metrics of each motion, on its 22 joints with the ground at y = 0 "
            "(CLoSD's joint-based protocol): penetration and floating beyond 5 mm, sliding of "
            "the lowest joint while within 5 mm of the ground (mm per frame), GMD skate ratio; "
            "never_touch is 1 when no joint comes within 0.10 m of the ground in any frame."
        ),
    )
    p.add_argument("files", type=Path, nargs="+", metavar="FILE", help="motion files (any format `simdiff convert` reads)")
    p.add_argument("--asf", type=Path, default=None, help="ASF skeleton for AMC inputs")
    p.add_argument("--json", action="store_true", help="print one JSON object per file instead of a table")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    import sys

    from simdiff.cli.feedback import slow_notice
    from simdiff.errors import SimdiffError
    from simdiff.motion.io import load_joints
    from simdiff.motion.metrics import never_touches, physics_metrics

    rows, failed = [], 0
    for i, path in enumerate(args.files):
        try:
            with slow_notice(f"reading {path} ({i + 1}/{len(args.files)})"):
                joints = load_joints(path, asf=args.asf)
                try:
                    values = physics_metrics(joints)
                except SimdiffError as exc:  # e.g. too few frames: name the file
                    raise SimdiffError(f"{path}: {exc}") from None
        except SimdiffError as exc:  # one line per bad file; the good files are still measured
            failed += 1
            print(f"simdiff: error: {exc}", file=sys.stderr)
            continue
        rows.append({"file": str(path), "frames": int(joints.shape[0]), **{k: float(v) for k, v in values.items()},
                     "never_touch": int(never_touches(joints)[0])})
    _print_rows(rows, args.json)
    return 2 if failed else 0


def _print_rows(rows: list[dict], as_json: bool) -> None:
    """The metrics as a table (or one JSON object per file)."""
    if as_json:
        for row in rows:
            print(json.dumps(row))
        return
    if not rows:
        return
    keys = [k for k in rows[0] if k not in ("file",)]
    width = max(len("file"), *(len(r["file"]) for r in rows))
    print("file".ljust(width) + "".join(f"{k:>16}" for k in keys))
    for row in rows:
        cells = "".join(f"{row[k]:>16d}" if isinstance(row[k], int) else f"{row[k]:>16.3f}" for k in keys)
        print(row["file"].ljust(width) + cells)
