"""``simdiff track FILE...``: replay motions in the physics simulator under φ (the projection P_φ)."""

from __future__ import annotations

import argparse
import json
import math
import os
from pathlib import Path

from simdiff.cli.options import add_environment_options

from simdiff.errors import SimdiffError

def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser(
        "track",
        help="track motions with the MuJoCo humanoid under gravity and wind (physics projection)",
        description=(
            "Replay each motion (any file `simdiff convert` reads) with the simulated humanoid and "
            "the default PD tracker under environment φ = (gravity, wind). Prints per motion: success, "
            "fall frame, d_L2, mean tracking error (mm), residual force (fraction of m·g) and torque, "
            "CPU seconds."
        ),
    )
    p.add_argument("files", nargs="+", type=Path, metavar="FILE", help="motion files")
    add_environment_options(p)
    p.add_argument("--residual", type=float, default=0.5, metavar="R",
                   help="root residual bound as a fraction of m·g (torque bound 600·R N·m); 0 = strict (default 0.5)")
    p.add_argument("--out", type=Path, default=None, metavar="DIR", help="write each rollout as DIR/<name>.npy joints")
    p.add_argument("--json", action="store_true", help="print one JSON object per motion")
    p.add_argument("--stats", type=Path, default=None, metavar="DIR",
                   help="folder with Mean.npy/Std.npy for d_L2 (default: $SIMDIFF_STATS, else the statistics shipped with simdiff)")
    p.add_argument("--force", action="store_true", help="allow φ outside the validated ranges")
    p.add_argument("--follow-flights", action="store_true",
                   help="let flights last as long as gravity makes them (the rollout may be longer than the input)")
    p.add_argument("--fps", type=float, default=None, help="source frame rate when the file does not say")
    p.set_defaults(func=run)


def _normalizer(arg: Path | None):
    """d_L2's normaliser: --stats, else $SIMDIFF_STATS, else the shipped CMU-corpus statistics."""
    from simdiff.motion.normalize import Normalizer, default_normalizer

    path = arg if arg is not None else (Path(os.environ["SIMDIFF_STATS"]) if os.environ.get("SIMDIFF_STATS") else None)
    return Normalizer.from_dir(path) if path is not None else default_normalizer()


def run(args: argparse.Namespace) -> int:
    import numpy as np

    from simdiff.sim.env import Environment
    from simdiff.sim.project import project
    from simdiff.sim.flight import FlightConfig
    from simdiff.sim.residual import ResidualConfig

    if args.residual < 0:
        raise SimdiffError(f"--residual must be ≥ 0, got {args.residual}")
    env = Environment(args.gravity, float(args.wind[0]), float(args.wind[1])).validate(force=args.force)
    from simdiff.motion.io import load_joints

    normalizer = _normalizer(args.stats)
    if args.out is not None:
        args.out.mkdir(parents=True, exist_ok=True)
    n_ok = 0
    for path in args.files:
        joints = np.asarray(load_joints(path, fps=args.fps), dtype=np.float64)
        out, info = project(joints, env, residual=ResidualConfig(max_force=args.residual), normalizer=normalizer,
                            force=args.force, flight=FlightConfig() if args.follow_flights else None)
        n_ok += info.success
        written = None
        if args.out is not None:
            written = args.out / f"{path.stem}.npy"
            tmp = written.with_suffix(".tmp.npy")
            np.save(tmp, out.astype(np.float32))
            os.replace(tmp, written)
        r = info.residual
        if args.json:
            d = info.to_dict()
            d["file"] = str(path)
            d["out"] = None if written is None else str(written)
            print(json.dumps(d, default=lambda x: None if isinstance(x, float) and math.isnan(x) else x))
        else:
            fall = "-" if info.fall_frame is None else str(info.fall_frame)
            print(
                f"{path.name}: {'OK  ' if info.success else info.status.upper()} fall={fall} "
                f"d_L2={info.d_l2:.3f} err={info.err_mm:.1f}mm (local {info.err_local_mm:.1f}) "
                f"residual F={r['force_mean_mg']:.3f}/{r['force_peak_mg']:.3f}mg "
                f"tau={r['torque_mean_nm']:.0f}/{r['torque_peak_nm']:.0f}Nm "
                f"cpu={info.cpu_s:.2f}s ({info.cpu_s / max(info.duration_s, 1e-9):.2f}s/s)"
            )
    if not args.json:
        print(f"tracked {n_ok}/{len(args.files)} under g={env.gravity} wind=({env.wind_x}, {env.wind_y}) N "
              f"residual={args.residual}")
    return 0
