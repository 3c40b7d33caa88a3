"""Session 82: what "a person runs forward" does under g -1.6 vs Earth, beyond the glide / never-touch counts.
Per sample (joints .npy, frames x 22 x 3, metres, Y-up, 20 fps): pelvis horizontal speed (m/s), the mean speed of the
joints relative to the pelvis (m/s; a frozen pose carried along scores near 0), and the share of frames with every
foot joint (7, 8, 10, 11) above 5 cm of the sample's lowest foot height (in the air).
Usage: python lowrun.py DIR [DIR ...]   (folders of `simdiff generate --format npy`)"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

FEET = [7, 8, 10, 11]


def figures(j: np.ndarray) -> tuple[float, float, float]:
    """(pelvis speed m/s, root-relative joint speed m/s, airborne share) of one sample."""
    v = np.linalg.norm(np.diff(j[:, 0, [0, 2]], axis=0), axis=1).mean() * 20
    rel = j - j[:, :1]
    w = np.linalg.norm(np.diff(rel, axis=0), axis=2).mean() * 20
    feet = j[:, FEET, 1]
    air = (feet.min(axis=1) > feet.min() + 0.05).mean()
    return float(v), float(w), float(air)


for d in sys.argv[1:]:
    rows = np.array([figures(np.load(f)) for f in sorted(Path(d).glob("sample*_joints.npy"))])
    q = np.percentile(rows, [25, 50, 75], axis=0)
    print(f"{d}: n {len(rows)}  pelvis m/s {q[1, 0]:.2f} [{q[0, 0]:.2f}, {q[2, 0]:.2f}]  "
          f"pose m/s {q[1, 1]:.2f} [{q[0, 1]:.2f}, {q[2, 1]:.2f}]  airborne {q[1, 2]:.2f} [{q[0, 2]:.2f}, {q[2, 2]:.2f}]")
