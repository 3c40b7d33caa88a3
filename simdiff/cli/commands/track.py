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
    p.add_argument("--fps", type=float, default=None, help="source frame rate when the file does not say")
    p.add_argument("--workers", type=int, default=1, metavar="N",
                   help="motions tracked in parallel processes; 0 = one per CPU core (default 1); results do not depend on N")
    p.set_defaults(func=run)


def _normalizer(arg: Path | None):
    """d_L2's normaliser: --stats, else $SIMDIFF_STATS, else the shipped CMU-corpus statistics."""
    from simdiff.motion.normalize import Normalizer, default_normalizer

    path = arg if arg is not None else (Path(os.environ["SIMDIFF_STATS"]) if os.environ.get("SIMDIFF_STATS") else None)
    return Normalizer.from_dir(path) if path is not None else default_normalizer()


def _stats_dir(arg: Path | None) -> Path:
    """d_L2's statistics folder: --stats, else $SIMDIFF_STATS, else the shipped CMU-corpus statistics."""
    from simdiff.motion.normalize import DEFAULT_STATS_DIR

    if arg is not None:
        return arg
    env = os.environ.get("SIMDIFF_STATS")
    return Path(env) if env else Path(DEFAULT_STATS_DIR)


def run(args: argparse.Namespace) -> int:
    import numpy as np
    from tqdm.auto import tqdm

    from simdiff.motion.io import load_joints
    from simdiff.sim.env import Environment
    from simdiff.sim.pool import PoolConfig, ProjectionPool
    from simdiff.sim.residual import ResidualConfig

    if args.residual < 0:
        raise SimdiffError(f"--residual must be ≥ 0, got {args.residual}")
    if args.workers < 0:
        raise SimdiffError(f"--workers must be ≥ 0 (0 = one per CPU core), got {args.workers}")
    env = Environment(args.gravity, float(args.wind[0]), float(args.wind[1])).validate(force=args.force)
    stats = _stats_dir(args.stats)
    _normalizer(stats)  # a bad --stats fails here, before any slow work
    if args.out is not None:
        from simdiff.fsio import check_writable, ensure_dir

        ensure_dir(args.out)
        check_writable(args.out / f"{args.files[0].stem}.npy")
    motions = [np.asarray(load_joints(path, fps=args.fps), dtype=np.float32) for path in args.files]
    pool = ProjectionPool(PoolConfig(workers=args.workers, residual=ResidualConfig(max_force=args.residual),
                                     stats_dir=str(stats), force=args.force))

    def progress(results):
        return tqdm(results, total=len(motions), desc=f"tracking ({pool_workers(args.workers, len(motions))} workers)",
                    unit="motion", leave=False, dynamic_ncols=True)

    results = pool.map(motions, env, progress=progress)
    n_ok = n_err = 0
    for path, (out, info) in zip(args.files, results):
        if isinstance(info, str):  # the pool turns a failed motion into its error message
            n_err += 1
            print(f"{path.name}: ERROR {info}" if not args.json else json.dumps({"file": str(path), "error": info}))
            continue
        n_ok += info.success
        written = None
        if args.out is not None:
            from simdiff.fsio import save_npy

            written = save_npy(args.out / f"{path.stem}.npy", out.astype(np.float32))
        _report(path, info, written, args.json)
    if not args.json:
        print(f"tracked {n_ok}/{len(args.files)} under g={env.gravity} wind=({env.wind_x}, {env.wind_y}) N "
              f"residual={args.residual}" + (f"; {n_err} failed" if n_err else ""))
    return 1 if n_err else 0


def pool_workers(requested: int, n_tasks: int) -> int:
    """Processes a pool of ``requested`` workers (0 = one per core) uses for ``n_tasks`` motions."""
    return max(1, min(requested or os.cpu_count() or 1, n_tasks))


def _report(path: Path, info, written: Path | None, as_json: bool) -> None:
    """One line (or one JSON object) per tracked motion."""
    r = info.residual
    if as_json:
        d = info.to_dict()
        d["file"] = str(path)
        d["out"] = None if written is None else str(written)
        print(json.dumps(d, default=lambda x: None if isinstance(x, float) and math.isnan(x) else x))
        return
    fall = "-" if info.fall_frame is None else str(info.fall_frame)
    print(
        f"{path.name}: {'OK  ' if info.success else info.status.upper()} fall={fall} "
        f"d_L2={info.d_l2:.3f} err={info.err_mm:.1f}mm (local {info.err_local_mm:.1f}) "
        f"residual F={r['force_mean_mg']:.3f}/{r['force_peak_mg']:.3f}mg "
        f"tau={r['torque_mean_nm']:.0f}/{r['torque_peak_nm']:.0f}Nm "
        f"cpu={info.cpu_s:.2f}s ({info.cpu_s / max(info.duration_s, 1e-9):.2f}s/s)"
    )
