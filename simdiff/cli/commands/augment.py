"""``simdiff data augment``: replay a corpus's training clips in the simulator under φ and keep the good rollouts."""

from __future__ import annotations

import argparse
from pathlib import Path

from simdiff.cli.main import command_group
from simdiff.cli.options import SEED, WORKERS, integer, real
from simdiff.sim.env import MAX_GRAVITY, MIN_FORCED_GRAVITY

MAX_CONDITIONS = 100
"""Most conditions per clip (paired) or in the shared list (random/paper: the paper's grid has 30)."""
MAX_SHARD_SIZE = 10_000
"""Most source clips per shard."""
MAX_CLIPS = 10_000_000
"""Largest --limit."""
MAX_THRESHOLD = 1e9
"""Largest keep threshold (--max-pose-d-l2, --max-d-l2 in normalised units, --max-residual-n in newtons): in
effect no bound (kept pairs have d_L2 below 10, residuals below the body's 700 N weight); nan and inf are refused."""
MAX_RESIDUAL_FRACTION = 10.0
"""Largest residual bound as a fraction of m·|g_z|."""


def register(subparsers: argparse._SubParsersAction) -> None:
    group = command_group(subparsers, "data", "build and augment corpora")
    p = group.add_parser(
        "augment", help="simulator-augmented corpus: project training clips under gravity/wind, filter, write + φ",
        description="Project every training clip through the MuJoCo tracker at Earth and under K one-factor "
                    "environments drawn per clip (paired, default), all 30 of the paper's grid (paper), a shared "
                    "random list (random) or Earth only (binary); flights last as long as gravity makes them. Keep "
                    "pairs that tracked to the end, stay faithful in pose to the re-timed source and need a small "
                    "root residual; write them in the HumanML3D layout with env.json. Sharded and resumable: run "
                    "the same command again after an interruption. Every tracked pair's files are written; the "
                    "filter is applied when the run finalises, so re-running with other thresholds only "
                    "re-finalises (no simulation).")
    p.add_argument("--corpus", type=Path, required=True, help="source corpus (HumanML3D layout with Mean.npy/Std.npy)")
    p.add_argument("--out", type=Path, required=True, help="output folder (resumed if it exists)")
    p.add_argument("--mode", choices=["paired", "paper", "random", "binary"], default="paired",
                   help="paired: Earth + --conditions draws per clip (default); paper: every clip under all 30; "
                        "random: one shared list; binary: Earth only")
    p.add_argument("--conditions", type=integer(1, MAX_CONDITIONS),
                   help=f"paired: draws per clip (default 6); paper/random: list size (default 30); 1..{MAX_CONDITIONS}")
    p.add_argument("--split", default="train", help="source split to augment (default train)")
    p.add_argument("--workers", type=WORKERS, default=0, help="parallel simulations, 0..64 (default 0: all cores)")
    p.add_argument("--backend", choices=["process", "ray", "serial"], default="process", help="parallel backend (default process)")
    p.add_argument("--seed", type=SEED, default=0, help="seed of the environment draw, 0..2^32-1 (default 0)")
    p.add_argument("--max-pose-d-l2", type=_pose_bound,
                   help="largest pose d_L2 against the re-timed source (normalised units, 0..1e9), or 'auto' (default in "
                        "paired/binary mode; random/paper modes have no Earth pairs and default to 5.2): "
                        "the smallest bound at which this run's Earth keep rate reaches --earth-keep (when fewer "
                        "Earth pairs tracked with an acceptable residual: the largest pose d_L2 among those); the "
                        "report gives the calibrated value and the achieved rate")
    p.add_argument("--earth-keep", type=real(0.0, 1.0, above=True), default=0.66,
                   help="auto: target Earth keep rate in (0, 1] (default 0.66, that of a filter without the flight clock, d_L2 <= 7 "
                        "and residual <= 0.1*m*|g_z|)")
    p.add_argument("--max-residual-n", type=real(0.0, MAX_THRESHOLD),
                   help="largest mean root residual force kept, newtons, 0..1e9 (default: FilterConfig's, 70.6); above Earth "
                        "gravity times s = |g_z|/9.81, the body-strength factor (simdiff.sim.strength)")
    p.add_argument("--residual-fixed", action="store_true",
                   help="keep --max-residual-n unchanged above Earth gravity too (no strength scaling)")
    p.add_argument("--max-d-l2", type=real(0.0, MAX_THRESHOLD),
                   help="also require the paper's d_L2 <= this, 0..1e9 (e.g. 7.0; default off)")
    p.add_argument("--max-residual", type=real(0.0, MAX_RESIDUAL_FRACTION),
                   help="also require the residual <= this fraction of m*|g_z|, 0..10 (default off)")
    p.add_argument("--residual-bound", type=real(0.0, MAX_RESIDUAL_FRACTION), default=0.5,
                   help="tracker's root residual bound, fraction of m*|g_z|, 0..10 (default 0.5; 0 = strict, no residual)")
    p.add_argument("--shard-size", type=integer(1, MAX_SHARD_SIZE), default=4,
                   help=f"source clips per shard, 1..{MAX_SHARD_SIZE} (default 4)")
    p.add_argument("--per-clip", type=integer(1, MAX_CONDITIONS),
                   help="random mode: project each clip under this many of the conditions, balanced "
                        "round-robin (default: all of them; the paper's full cross product)")
    p.add_argument("--share-mirrors", action="store_true",
                   help="paired/binary: derive each mirrored clip M<id> from <id>'s rollouts under mirror(phi) "
                        "(w_x negated) instead of simulating it (the simulator is left-right symmetric: "
                        "0.000 mm apart on 24 of 24 measured pairs); M<id>'s conditions are then mirror(<id>'s)")
    p.add_argument("--resimulate-gravity-below", type=real(MIN_FORCED_GRAVITY, MAX_GRAVITY), metavar="G",
                   help="in an existing run, re-simulate the pairs with g_z < G (m/s^2, -100..-0.1) made by an older simulator "
                        "version (records' sim_version), re-derive their mirrors, rewrite their files and shards, "
                        "then finalise; resumable. -9.81: exactly the pairs changed by the gravity-scaled "
                        "actuators (simdiff.sim.strength)")
    p.add_argument("--no-retime", action="store_true",
                   help="one try per pair: do not retry a weak-gravity (|g_z| < 9.81) rollout that fell or strayed on "
                        "the source slowed to the same Froude number (simdiff.sim.retime; on by default). A run made "
                        "without retiming resumes only with this flag")
    p.add_argument("--factors", nargs="+", metavar="FACTOR",
                   help="paired: draw only these factors (gravity, wind_x, wind_y; default all three, cycled)")
    p.add_argument("--gravity-range", nargs=2, type=real(MIN_FORCED_GRAVITY, MAX_GRAVITY), metavar=("LO", "HI"),
                   help="paired: draw g_z uniformly in [LO, HI] m/s^2 (default -20 -1), e.g. -5 -1 for weak gravity; "
                        "LO = HI: that one gravity (with --conditions at most the number of factors)")
    p.add_argument("--limit", type=integer(1, MAX_CLIPS), help="augment only the first N clips of the split")
    p.add_argument("--no-progress", action="store_true", help="hide the progress bar")
    p.set_defaults(func=run)


def _pose_bound(text: str) -> float | str:
    """``--max-pose-d-l2``: ``auto`` or a number in [0, :data:`MAX_THRESHOLD`]."""
    if text == "auto":
        return text
    try:
        return real(0.0, MAX_THRESHOLD)(text)
    except argparse.ArgumentTypeError as exc:
        raise argparse.ArgumentTypeError(f"{exc} (a number in [0, {MAX_THRESHOLD:g}] or 'auto')") from None


def run(args: argparse.Namespace) -> int:
    from simdiff.data.augment.conditions import FACTORS
    from simdiff.data.augment.filter import AUTO, FilterConfig
    from simdiff.sim.env import GRAVITY_RANGE
    from simdiff.data.augment.run import AugmentConfig, augment

    defaults = FilterConfig()
    pose = args.max_pose_d_l2
    if pose is None:
        pose = AUTO if args.mode in ("paired", "binary") else defaults.max_pose_d_l2
    residual_n = defaults.max_residual_n if args.max_residual_n is None else args.max_residual_n
    factors = FACTORS if args.factors is None else tuple(args.factors)
    gravity_range = GRAVITY_RANGE if args.gravity_range is None else tuple(args.gravity_range)
    config = AugmentConfig(mode=args.mode, conditions=args.conditions, seed=args.seed, split=args.split,
                           shard_size=args.shard_size, limit=args.limit,
                           filter=FilterConfig(max_pose_d_l2=pose, earth_keep=args.earth_keep, max_residual_n=residual_n,
                                               max_d_l2=args.max_d_l2, max_residual=args.max_residual,
                                               residual_follows_strength=not args.residual_fixed),
                           residual_bound=args.residual_bound, workers=args.workers, backend=args.backend,
                           per_clip=args.per_clip, share_mirrors=args.share_mirrors,
                           resimulate_gravity_below=args.resimulate_gravity_below, retime=not args.no_retime,
                           factors=factors, gravity_range=gravity_range)
    from simdiff.sim.pool import WorkerDied, stop_signals, stopped

    try:
        with stop_signals():
            report = augment(args.corpus, args.out, config, progress=not args.no_progress)
    except (KeyboardInterrupt, WorkerDied) as exc:  # workers already stopped; the finished shards are kept
        return stopped(exc)
    frac = report["kept_fraction"]
    cal = report["filter"].get("calibration")
    if cal is not None:
        print(f"pose d_L2 threshold (auto): {cal['max_pose_d_l2']:.4g}; Earth keep rate "
              f"{100 * cal['earth_keep_achieved']:.1f} % (target {100 * cal['earth_keep_target']:.1f} %)")
    print(f"kept {report['kept']}/{report['pairs']} pairs" + (f" ({100 * frac:.1f} %)" if frac is not None else "")
          + f" from {report['clips']} clips; corpus: {args.out} (report: {args.out / 'report.md'})")
    return 0
