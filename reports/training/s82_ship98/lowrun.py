"""Session 82: what "a person runs forward" does under g -1.6 vs Earth, beyond the glide / never-touch counts.
Per sample (joints .npy, frames x 22 x 3, metres, Y-up, 20 fps): pelvis horizontal speed (m/s), the mean speed of the
joints relative to the pelvis (m/s; a frozen pose carried along scores near 0), and the share of frames in a flight
(the model check's own rules: `root_speed`, `simdiff.motion.flight.airborne`).
Usage: python lowrun.py DIR [DIR ...]   (folders of `simdiff generate --format npy`)"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from simdiff.eval.model_check.detect import root_speed
from simdiff.motion.flight import airborne
from simdiff.motion.skeleton import FPS


def figures(j: np.ndarray) -> tuple[float, float, float]:
    """(pelvis speed m/s, root-relative joint speed m/s, airborne share) of one sample."""
    pose_speed = np.linalg.norm(np.diff(j - j[:, :1], axis=0), axis=2).mean() * FPS
    return root_speed(j), float(pose_speed), float(airborne(j).mean())


for d in sys.argv[1:]:
    rows = np.array([figures(np.load(f)) for f in sorted(Path(d).glob("sample*_joints.npy"))])
    q = np.percentile(rows, [25, 50, 75], axis=0)
    print(f"{d}: n {len(rows)}  pelvis m/s {q[1, 0]:.2f} [{q[0, 0]:.2f}, {q[2, 0]:.2f}]  "
          f"pose m/s {q[1, 1]:.2f} [{q[0, 1]:.2f}, {q[2, 1]:.2f}]  airborne {q[1, 2]:.2f} [{q[0, 2]:.2f}, {q[2, 2]:.2f}]")
