"""``simdiff convert IN OUT``: motion files to HumanML3D joints or features (.npy), BVH or glTF binary (.glb)."""

from __future__ import annotations

import argparse
from pathlib import Path

from simdiff.cli.options import FPS_OPTION
from simdiff.errors import SimdiffError


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser(
        "convert",
        help="convert a motion file (AMC, BVH, DeepMimic JSON, .npy) to .npy joints/features, .bvh or .glb",
        description=(
            "Convert a motion to the 22-joint HumanML3D skeleton (metres, Y-up, 20 fps). IN: AMC "
            "(with its ASF), BVH, DeepMimic JSON, .npy joints (T,22,3) or un-normalised "
            "HumanML3D features (T,263). OUT: .npy (joints or features, see --to), .bvh, or .glb (glTF 2.0 "
            "binary: the skeleton with a skinned body, animated on the motion's own mean bone lengths)."
        ),
    )
    p.add_argument("input", type=Path, metavar="IN", help="motion file to read")
    p.add_argument("output", type=Path, metavar="OUT", help="file to write: .npy, .bvh or .glb")
    p.add_argument(
        "--to",
        choices=("joints", "features"),
        default="joints",
        help="for .npy output: joints (T,22,3) or HumanML3D features (T-1,263) (default: joints)",
    )
    p.add_argument("--asf", type=Path, default=None, help="ASF skeleton for an AMC input (default: SS.asf beside it or in ../asf/)")
    p.add_argument("--fps", type=FPS_OPTION, default=None, help="source frame rate in Hz, overriding the file's own (BVH Frame Time; AMC: CMU_data.csv, a _120 name, else 120; .npy: 20)")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    import numpy as np

    from simdiff.cli.feedback import slow_notice
    from simdiff.fsio import check_writable, save_npy
    from simdiff.motion.io import load_joints, write_bvh

    suffix = args.output.suffix.lower()
    if suffix not in (".npy", ".bvh", ".glb"):
        raise SimdiffError(f"unsupported output type {args.output.name!r}: use .npy, .bvh or .glb")
    if suffix != ".npy" and args.to == "features":
        raise SimdiffError(f"--to features needs a .npy output, not {suffix}")
    check_writable(args.output)
    with slow_notice(f"reading {args.input}"):
        joints = load_joints(args.input, asf=args.asf, fps=args.fps)
    if suffix == ".bvh":
        with slow_notice(f"writing {args.output}"):
            write_bvh(args.output, joints)
        what = f"BVH, {joints.shape[0]} frames"
    elif suffix == ".glb":
        from simdiff.motion.io.gltf_writer import write_glb
        from simdiff.motion.rigid import fit

        with slow_notice(f"writing {args.output}"):
            write_glb(args.output, fit(joints, None))
        what = f"glTF binary, skinned body, {joints.shape[0]} frames"
    elif args.to == "features":
        from simdiff.motion.features import joints_to_features  # torch: only for features

        with slow_notice("computing HumanML3D features"):
            feats = joints_to_features(joints)
        save_npy(args.output, feats.astype(np.float32))
        what = f"features {feats.shape}"
    else:
        save_npy(args.output, joints)
        what = f"joints {joints.shape}"
    print(f"wrote {args.output} ({what})")
    return 0
