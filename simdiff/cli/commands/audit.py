"""``simdiff audit FILE...``: physics metrics, inverse-dynamics residual and a tracking rollout of motions."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from simdiff.cli.options import FPS_OPTION, add_environment_options, real

from simdiff.errors import SimdiffError


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``simdiff audit``."""
    p = subparsers.add_parser(
        "audit",
        help="how physical is a motion: metrics, inverse-dynamics residual, tracking in the simulator",
        description=(
            "For each motion (any file `simdiff convert` reads): the physics metrics (penetration, "
            "floating, sliding, skate ratio); the inverse-dynamics root residual of its tracking "
            "reference under φ, i.e. the external force (fraction of m·|g|) and torque (N·m) that "
            "gravity, wind and floor contacts cannot supply (mean, p90, peak, share of frames above "
            "0.1 m·g); and the result of tracking it with the simulated humanoid under φ (as "
            "`simdiff track`). With --out: a plot, the rollout joints and, with --render, a body "
            "render of the input next to the rollout."
        ),
    )
    p.add_argument("files", nargs="+", type=Path, metavar="FILE", help="motion files")
    add_environment_options(p)
    p.add_argument("--residual", type=real(0.0, 1e6), default=0.5, metavar="R",
                   help="tracking: root residual bound as a fraction of m·g; 0 = strict (default 0.5)")
    p.add_argument("--out", type=Path, default=None, metavar="DIR",
                   help="write DIR/<name>_audit.png, <name>_audit.json and <name>_rollout.npy")
    p.add_argument("--render", action="store_true",
                   help="with --out: also DIR/<name>_body.mp4, the input (blue) beside the rollout (orange)")
    p.add_argument("--json", action="store_true", help="print one JSON object per motion")
    p.add_argument("--no-track", dest="track", action="store_false",
                   help="skip the simulator (metrics and inverse-dynamics residual only)")
    p.add_argument("--asf", type=Path, default=None, help="ASF skeleton for AMC inputs")
    p.add_argument("--fps", type=FPS_OPTION, default=None, help="source frame rate in Hz, overriding the file's own (BVH Frame Time; AMC: CMU_data.csv, a _120 name, else 120; .npy: 20)")
    p.add_argument("--stats", type=Path, default=None, metavar="DIR",
                   help="Mean.npy/Std.npy for d_L2 (default: $SIMDIFF_STATS, else the statistics shipped with simdiff)")
    p.add_argument("--force", action="store_true", help="allow φ outside the validated ranges")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from simdiff.fsio import check_writable
    from simdiff.sim.env import Environment

    if args.residual < 0:
        raise SimdiffError(f"--residual must be ≥ 0, got {args.residual}")
    if args.render and args.out is None:
        raise SimdiffError("--render needs --out DIR")
    env = Environment(args.gravity, float(args.wind[0]), float(args.wind[1])).validate(force=args.force)
    from simdiff.motion.io import check_regular_file

    for path in args.files:  # fail on a missing file, a folder or a device before any slow work
        check_regular_file(path)
    normalizer = None
    if args.track:
        from simdiff.cli.commands.track import _normalizer

        normalizer = _normalizer(args.stats)
    if args.out is None:
        return _audit_all(args, env, normalizer)
    from simdiff.cli.commands.track import check_unique_outputs
    from simdiff.data.writer import cleaned_on_failure

    check_unique_outputs(args.files, args.out, "_audit.json")
    done: list[Path] = []
    with cleaned_on_failure(args.out, keep=lambda: bool(done)):  # a run that audits nothing leaves no folder
        check_writable(args.out / f"{args.files[0].stem}_audit.json")
        return _audit_all(args, env, normalizer, done)


def _audit_all(args: argparse.Namespace, env, normalizer, done: list[Path] | None = None) -> int:
    """Audit every file in turn; ``done`` collects the files audited (their outputs written)."""
    from simdiff.eval.audit import audit_motion, plot_audit
    from simdiff.fsio import save_npy, write_json
    from simdiff.motion.io import load_joints
    from simdiff.sim.residual import ResidualConfig

    for path in args.files:
        joints = load_joints(path, asf=args.asf, fps=args.fps)
        audit = audit_motion(joints, env, name=path.name, residual=ResidualConfig(max_force=args.residual),
                             track=args.track, normalizer=normalizer, force=args.force, progress=not args.json)
        record = audit.to_dict()
        if args.out is not None:
            stem = path.stem
            record["plot"] = str(plot_audit(audit, args.out / f"{stem}_audit.png"))
            if audit.rollout is not None:
                target = save_npy(args.out / f"{stem}_rollout.npy", audit.rollout.astype("float32"))
                record["rollout"] = str(target)
            if args.render:
                record["render"] = str(_render(joints, audit, args.out / f"{stem}_body.mp4", not args.json))
            write_json(args.out / f"{stem}_audit.json", record, indent=1)
        if args.json:
            print(json.dumps(record))
        else:
            print(audit.table())
            for key in ("plot", "rollout", "render"):
                if key in record:
                    print(f"  wrote {record[key]}")
        if done is not None:
            done.append(path)
    return 0


def _render(joints, audit, target: Path, progress: bool) -> Path:
    """Body render of the input beside the rollout (the input alone with --no-track)."""
    from simdiff.viz.body import render_body

    motions, captions = [joints], ["input"]
    if audit.rollout is not None and len(audit.rollout) > 0:
        motions.append(audit.rollout)
        captions.append("rollout" if audit.tracking["success"] else f"rollout ({audit.tracking['status']})")
    return render_body(motions, target, captions=captions, size=(480, 400), progress=progress)
