"""Command-line options shared by several commands."""

from __future__ import annotations

import argparse


def add_environment_options(p: argparse.ArgumentParser) -> None:
    """``--gravity G`` (m/s², default Earth) and ``--wind X Y`` (N) for commands that simulate."""
    p.add_argument("--gravity", type=float, default=-9.81, help="vertical gravity g_z in m/s² (default -9.81)")
    p.add_argument("--wind", type=float, nargs=2, default=(0.0, 0.0), metavar=("X", "Y"),
                   help="wind force in N along HumanML3D +X (left) and +Z (forward) (default 0 0)")
