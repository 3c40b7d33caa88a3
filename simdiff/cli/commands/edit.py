"""``simdiff edit MOTION --gravity G --wind X Y``: an existing motion re-played under another gravity and wind."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from simdiff.cli.options import FPS_OPTION, SEED, add_environment_options
from simdiff.inference.editing import HALVES

EPILOG = """\
outputs (in --out, default ./out/<motion>_edit/):
  edited_joints.npy     (T, 22, 3) joint positions, metres, Y-up, 20 fps, in the input's frame and skeleton
  edited_features.npy   (T, 263) un-normalised HumanML3D features of the edit (canonical frame)
  edited.bvh            BVH animation (metres, Y-up, 20 fps)
  compare.gif           the input (left) and the edit (right), one camera
  edit.json             input, environment, seed, text, sampling, model, how far the motion moved, the gravity
                        read from its flights before and after, timings

At Earth's gravity without wind the input comes back unchanged. Motions longer than 9.8 s are re-played in
overlapping windows.

examples:
  simdiff edit jump.bvh --gravity -1.6
  simdiff edit walk.npy --wind 0 8 --text "a person walks forward"
  simdiff edit 13_29.amc --asf 13.asf --gravity -3.7 --format npy,bvh,glb
  simdiff edit walk.bvh --keep lower --text "a person waves with both hands"
"""


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser(
        "edit",
        help="re-play an existing motion under another gravity and wind, or remake half of its body",
        description="Re-play a motion file (.npy joints or features, BVH, AMC with --asf, DeepMimic) under gravity\n"
                    "and wind with the default model (or --model / $SIMDIFF_MODEL): its path, timing and style\n"
                    "are kept, and only what the environment changes changes. With --keep lower|upper and --text,\n"
                    "one half of the body is kept and the other made anew for the text.",
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("motion", type=Path, metavar="MOTION", help="motion file to re-play")
    env = p.add_argument_group("environment φ")
    add_environment_options(env)
    env.add_argument("--force", action="store_true",
                     help="allow environments outside the trained range (gravity -20..-1 m/s², |wind| <= 10 N)")
    inp = p.add_argument_group("input and sampling")
    inp.add_argument("--asf", type=Path, default=None, help="ASF skeleton for an AMC input")
    inp.add_argument("--fps", type=FPS_OPTION, default=None, help="source frame rate in Hz, overriding the file's own")
    inp.add_argument("--text", default="", metavar="TEXT",
                     help="what the motion shows, e.g. \"a person jumps forward\" (optional; it steers the model's "
                          "answer to φ)")
    inp.add_argument("--keep", choices=HALVES, metavar="lower|upper",
                     help="keep this half of the body (lower: pelvis and legs; upper: pelvis, spine, head and arms) and "
                          "make the other anew for --text (longer than 9.8 s: in windows that continue each other)")
    inp.add_argument("--seed", type=SEED, default=0, metavar="S", help="noise seed (default 0)")
    out = p.add_argument_group("output")
    out.add_argument("--out", type=Path, metavar="DIR", help="output folder, files in it are replaced (default "
                                                            "./out/<motion>_edit)")
    out.add_argument("--format", metavar="LIST", help="comma-separated outputs among npy, bvh, glb, gif, mp4 "
                                                      "(default npy,bvh,gif)")
    out.add_argument("-q", "--quiet", action="store_true", help="no notes (warnings still show); print only the paths")
    run_ = p.add_argument_group("model and compute")
    run_.add_argument("--model", type=Path, metavar="DIR", help="model folder (default $SIMDIFF_MODEL, else the "
                                                                "shipped model)")
    run_.add_argument("--device", default="cpu", help="torch device, e.g. cpu or cuda (default cpu)")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    import time

    from simdiff.product.request import check_text, environments, parse_formats

    start = time.perf_counter()
    env = environments(args.gravity, tuple(args.wind), None, args.force)[0]  # checked before torch loads
    formats = parse_formats(args.format)
    text = check_text(args.text) if args.text.strip() or args.keep else ""
    if not args.motion.is_file():
        from simdiff.errors import SimdiffError

        raise SimdiffError(f"no motion file {str(args.motion)!r}")
    from simdiff.cli.feedback import slow_notice
    from simdiff.inference.editing import check_motion
    from simdiff.motion.io import load_joints

    with slow_notice(f"reading {args.motion}"):
        joints = check_motion(load_joints(args.motion, asf=args.asf, fps=args.fps), str(args.motion))
    from simdiff.product.edit import EditRequest, edit_file
    from simdiff.product.outputs import fresh_dir, slug

    out_dir = args.out if args.out is not None else fresh_dir(Path("out") / f"{slug(args.motion.stem)}_edit")
    request = EditRequest(args.motion, joints, env, formats, text, args.seed, args.keep)
    paths, summary = edit_file(request, out_dir, model=args.model, device=args.device, quiet=args.quiet)
    for path in paths:
        print(path)
    if not args.quiet:
        print(f"simdiff: {summary} in {time.perf_counter() - start:.1f} s", file=sys.stderr)
    return 0
