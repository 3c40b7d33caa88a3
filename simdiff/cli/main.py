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
import signal
import sys
import threading
from typing import Sequence

from simdiff import __version__
from simdiff.cli.options import UsageError
from simdiff.errors import SimdiffError, Terminated

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
    from simdiff.cli.options import Parser

    parser = Parser(
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


def _terminate(signum: int, frame: object) -> None:
    raise Terminated()


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point: parse, dispatch, and turn user errors into one-line messages.

    SIGTERM is raised as :class:`~simdiff.errors.Terminated` (a ``KeyboardInterrupt``), so Ctrl-C and a kill
    both remove partial output and stop workers; exit codes 130 and 143 as a shell reports them.
    """
    parser = build_parser()
    main_thread = threading.current_thread() is threading.main_thread()
    previous = signal.signal(signal.SIGTERM, _terminate) if main_thread else None
    try:
        args, extra = parser.parse_known_args(argv)
        if extra:  # named here so that the hint points at the subcommand's own help
            sub = " ".join(str(v) for v in (args.command, getattr(args, f"{args.command}_command", None)) if v)
            raise UsageError(f"unrecognized arguments: {' '.join(extra)} (see simdiff {sub} --help)")
        return int(args.func(args) or 0)
    except SimdiffError as exc:
        print(f"simdiff: error: {exc}", file=sys.stderr)
        return 2
    except Terminated:
        print("simdiff: terminated", file=sys.stderr)
        return 143
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
    finally:
        if main_thread:
            signal.signal(signal.SIGTERM, previous)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
