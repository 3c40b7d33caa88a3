"""``simdiff generate TEXT``: text (+ gravity, wind) → motion with the shipped default model."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser(
        "generate",
        help="generate a motion from text under gravity and wind with the shipped default model",
        description="Generate a motion from a text prompt under explicit gravity and wind.",
    )
    p.add_argument("text", help='what the person does, e.g. "a person jumps forward"')
    p.add_argument("--gravity", type=float, default=-9.81, help="vertical gravity g_z in m/s² (default -9.81)")
    p.add_argument("--wind", type=float, nargs=2, default=(0.0, 0.0), metavar=("X", "Y"), help="horizontal wind force in newtons")
    p.add_argument("--out", type=Path, default=Path("out"), help="output folder (default: ./out)")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    import importlib
    import importlib.util

    if importlib.util.find_spec("simdiff.model.default") is None:  # arrives with the shipped weights
        print(
            "simdiff: no default model yet: the shipped weights arrive with the model and "
            "training work; meanwhile use `simdiff convert`, `simdiff metrics` and `simdiff render`.",
            file=sys.stderr,
        )
        return 1
    return importlib.import_module("simdiff.model.default").generate_cli(args)
