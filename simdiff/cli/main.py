"""The ``simdiff`` command.

Subcommands live one per module in :mod:`simdiff.cli.commands`; each module defines
``register(subparsers) -> None`` which adds its parser(s) and sets ``func`` (a callable
taking the parsed ``argparse.Namespace`` and returning an exit code). Modules import
heavy dependencies (torch, mujoco) inside ``func`` so that ``--help`` stays fast.
"""

from __future__ import annotations

import argparse
import importlib
import pkgutil
import sys
from typing import Sequence

from simdiff import __version__
from simdiff.errors import SimdiffError

def command_group(subparsers: argparse._SubParsersAction, name: str, help: str) -> argparse._SubParsersAction:
    """Return the sub-subparsers of group ``name`` (e.g. ``data``), creating it once.

    Lets several command modules add to one group (``simdiff data build``,
    ``simdiff data augment``) without knowing about each other.
    """
    groups: dict[str, argparse._SubParsersAction] = subparsers.__dict__.setdefault("_simdiff_groups", {})
    if name not in groups:
        parser = subparsers.add_parser(name, help=help, description=help)
        sub = parser.add_subparsers(dest=f"{name}_command", metavar="COMMAND")
        sub.required = True
        groups[name] = sub
    return groups[name]


def build_parser() -> argparse.ArgumentParser:
    """Build the full argument parser by discovering every command module."""
    parser = argparse.ArgumentParser(
        prog="simdiff",
        description="Physically plausible text-to-motion under gravity and wind, and the HumanML3D toolchain.",
    )
    parser.add_argument("--version", action="version", version=f"simdiff {__version__}")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND")
    subparsers.required = True
    from simdiff.cli import commands

    for info in sorted(pkgutil.iter_modules(commands.__path__), key=lambda m: m.name):
        module = importlib.import_module(f"{commands.__name__}.{info.name}")
        register = getattr(module, "register", None)
        if register is not None:
            register(subparsers)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point: parse, dispatch, and turn user errors into one-line messages."""
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.func(args) or 0)
    except SimdiffError as exc:
        print(f"simdiff: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("simdiff: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        return 0
    except OSError as exc:  # a read or write the command did not foresee: still one line, no traceback
        from simdiff.fsio import reason

        where = f"{exc.filename}: " if exc.filename else ""
        print(f"simdiff: error: {where}{reason(exc)}", file=sys.stderr)
        return 1


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
