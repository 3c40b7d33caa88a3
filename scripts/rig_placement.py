"""Where a retargeted rig puts the trunk and head joints, in SMPL's trunk frame.

For each file: ``load_joints`` (20 fps), then for upright frames (hip-centre -> neck within
25 deg of vertical) every upper-body joint is expressed in the trunk frame: origin at the
hip centre, unit length = hip centre -> neck, axes up (towards the neck), forward
(left x up, left = right hip -> left hip) and lateral (absolute, so both sides pool).
Prints per-source medians next to the real HumanML3D clip 012314 (SMPL joints), the
reference of reports/corpus/NOTES.md.

    python scripts/rig_placement.py --humanml3d ../shared/data/humanml3d FILE... [--label L]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

from simdiff.motion.io import load_joints
from simdiff.motion.skeleton import JOINT_NAMES

JOINTS: tuple[str, ...] = ("pelvis", "spine1", "spine2", "spine3", "left_collar", "head",
                           "left_shoulder", "left_hip")


def trunk_coordinates(joints: np.ndarray) -> dict[str, np.ndarray]:
    """Median (up, forward, lateral) trunk-frame coordinates of :data:`JOINTS`.

    Args:
        joints: (T, 22, 3) metres, Y-up.
    Returns:
        joint name -> (3,) (up, forward, |lateral|) in trunk lengths; also "trunk_m": (1,)
        the median trunk length in metres.
    """
    j = np.asarray(joints, dtype=np.float64)
    hip_c = 0.5 * (j[:, 1] + j[:, 2])
    axis = j[:, 12] - hip_c
    length = np.linalg.norm(axis, axis=-1, keepdims=True)
    up = axis / length
    left = j[:, 1] - j[:, 2]
    left -= (left * up).sum(-1, keepdims=True) * up
    left /= np.linalg.norm(left, axis=-1, keepdims=True)
    forward = np.cross(left, up)
    upright = up[:, 1] > np.cos(np.radians(25))
    if not upright.any():
        upright[:] = True
    out: dict[str, np.ndarray] = {"trunk_m": np.array([float(np.median(length[upright]))])}
    for name in JOINTS:
        rel = (j[:, JOINT_NAMES.index(name)] - hip_c) / length
        coords = np.stack([(rel * up).sum(-1), (rel * forward).sum(-1), np.abs((rel * left).sum(-1))], -1)
        out[name] = np.median(coords[upright], axis=0)
    return out


def report(label: str, rows: list[dict[str, np.ndarray]]) -> str:
    """One line per joint: median over files of (up, forward, lateral)."""
    lines = [f"{label} ({len(rows)} files, trunk {np.median([r['trunk_m'][0] for r in rows]):.3f} m)"]
    for name in JOINTS:
        v = np.median([r[name] for r in rows], axis=0)
        lines.append(f"  {name:14s} up {v[0]:+.3f}  fwd {v[1]:+.3f}  lat {v[2]:.3f}")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("files", nargs="*", type=Path)
    parser.add_argument("--label", default="files")
    parser.add_argument("--humanml3d", type=Path, default=None, help="shared humanml3d folder")
    args = parser.parse_args(argv)
    if args.humanml3d is not None:
        ref = np.load(args.humanml3d / "samples" / "new_joints" / "012314.npy")
        print(report("HumanML3D 012314 (SMPL)", [trunk_coordinates(ref)]))
    if args.files:
        print(report(args.label, [trunk_coordinates(load_joints(f)) for f in args.files]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
