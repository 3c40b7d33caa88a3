"""``simdiff track FILE...``: replay motions in the physics simulator under φ (the projection P_φ)."""

from __future__ import annotations

import argparse
import json
import math
import os
from pathlib import Path

from simdiff.cli.options import FPS_OPTION, WORKERS, add_environment_options, real
from simdiff.errors import SimdiffError

MAX_RESIDUAL: float = 10.0
"""Largest --residual (fraction of m·g; 0.5 is the default, 1 holds the body up at any gravity)."""


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
    p.add_argument("--residual", type=real(0.0, MAX_RESIDUAL), default=0.5, metavar="R",
                   help="root residual bound as a fraction of m·g, 0..10 (torque bound 600·R N·m); 0 = strict (default 0.5)")
    p.add_argument("--out", type=Path, default=None, metavar="DIR", help="write each rollout as DIR/<name>.npy joints")
    p.add_argument("--json", action="store_true", help="print one JSON object per motion")
    p.add_argument("--stats", type=Path, default=None, metavar="DIR",
                   help="folder with Mean.npy/Std.npy for d_L2 (default: $SIMDIFF_STATS, else the statistics shipped with simdiff)")
    p.add_argument("--force", action="store_true", help="allow φ outside the validated ranges")
    p.add_argument("--follow-flights", action="store_true",
                   help="let flights last as long as gravity makes them (the rollout may be longer than the input)")
    p.add_argument("--asf", type=Path, default=None, metavar="FILE",
                   help="ASF skeleton for AMC inputs (default: SS.asf beside each or in ../asf/)")
    p.add_argument("--fps", type=FPS_OPTION, default=None,
                   help="source frame rate in Hz, overriding the file's own (BVH Frame Time; AMC: CMU_data.csv, a _120 name, else 120; .npy: 20)")
    p.add_argument("--workers", type=WORKERS, default=1, metavar="N",
                   help="motions tracked in parallel processes, 0..64; 0 = one per CPU core (default 1); "
                        "results do not depend on N")
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
    from simdiff.sim.flight import FlightConfig
    from simdiff.sim.pool import PoolConfig, ProjectionPool, WorkerDied, note_progress, stop_signals, stopped
    from simdiff.sim.residual import ResidualConfig

    env = Environment(args.gravity, float(args.wind[0]), float(args.wind[1])).validate(force=args.force)
    stats = _stats_dir(args.stats)
    _normalizer(stats)  # a bad --stats fails here, before any slow work
    if args.out is not None:
        check_unique_outputs(args.files, args.out, ".npy")
    files, motions, n_bad = [], [], 0
    for path in args.files:  # a bad file is one line; the others are still tracked
        try:
            motions.append(np.asarray(load_joints(path, asf=args.asf, fps=args.fps), dtype=np.float32))
            files.append(path)
        except SimdiffError as exc:
            n_bad += 1
            _failed(path, str(exc), args.json)
    if not motions:
        return 2
    if args.out is not None:
        from simdiff.fsio import check_writable, ensure_dir

        ensure_dir(args.out)
        check_writable(args.out / f"{files[0].stem}.npy")
    pool = ProjectionPool(PoolConfig(workers=args.workers, residual=ResidualConfig(max_force=args.residual),
                                     stats_dir=str(stats), force=args.force,
                                     flight=FlightConfig() if args.follow_flights else None))

    def progress(results):
        return tqdm(results, total=len(motions), desc=f"tracking ({pool_workers(args.workers, len(motions))} workers)",
                    unit="motion", leave=False, dynamic_ncols=True)

    n_ok = n_err = done = 0
    try:
        with stop_signals():  # SIGTERM as Ctrl-C: stop the workers, one line, exit 143
            for path, (out, info) in zip(files, progress(pool.imap(motions, [env] * len(motions)))):
                done += 1
                if isinstance(info, str):  # the pool turns a failed motion into its error message
                    n_err += 1
                    _failed(path, f"{path}: cannot be tracked ({plain_error(info)})", args.json)
                    continue
                n_ok += info.success
                written = None
                if args.out is not None:
                    from simdiff.fsio import save_npy

                    written = save_npy(args.out / f"{path.stem}.npy", out.astype(np.float32))
                _report(path, info, written, args.json)
    except (KeyboardInterrupt, WorkerDied) as exc:
        pool.terminate()
        note_progress(exc, f"{done} of {len(motions)} motions done")
        return stopped(exc, resumable=False)
    finally:
        pool.close()
    if not args.json:
        print(f"tracked {n_ok}/{len(args.files)} under g={env.gravity} wind=({env.wind_x}, {env.wind_y}) N "
              f"residual={args.residual}" + (f"; {n_err + n_bad} failed" if n_err + n_bad else ""))
    return 2 if n_err + n_bad else 0


def plain_error(message: str) -> str:
    """A worker's ``"<ExceptionClass>: text"`` message without the Python class name."""
    head, sep, rest = message.partition(": ")
    if sep and head.isidentifier():
        return rest.strip() or "unknown failure"
    return message.strip() or "unknown failure"


def _failed(path: Path, message: str, as_json: bool) -> None:
    """One line for a motion that could not be read or tracked (JSON on stdout with --json, else stderr)."""
    import sys

    from tqdm.auto import tqdm

    if as_json:
        print(json.dumps({"file": str(path), "error": message}))
    else:
        tqdm.write(f"simdiff: error: {message}", file=sys.stderr)  # above a running progress bar


def check_unique_outputs(files: list[Path], out: Path, suffix: str) -> None:
    """Refuse inputs that would be written to the same ``out/<stem><suffix>`` (the second would overwrite the
    first)."""
    seen: dict[str, Path] = {}
    for path in files:
        name = f"{path.stem}{suffix}"
        if name in seen:
            raise SimdiffError(f"{seen[name]} and {path} would both be written to {out / name}: "
                               f"give inputs with different file names")
        seen[name] = path


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
