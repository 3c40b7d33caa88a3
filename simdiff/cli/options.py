"""Command-line options shared by several commands, and the checked number types every numeric option uses.

Every numeric option is parsed by :func:`integer` or :func:`real`: nan, inf and values outside the option's range
are refused by argparse before any work starts, with one line naming the option and the value.
"""

from __future__ import annotations

import argparse
import math
import re
from typing import Callable, NoReturn

from simdiff.errors import SimdiffError
from simdiff.diffusion.config import MAX_SEED
from simdiff.limits import MAX_FPS, MAX_WORKERS, MIN_FPS
from simdiff.sim.env import MAX_FORCED_WIND, MAX_GRAVITY, MIN_FORCED_GRAVITY

MAX_TRAIN_BATCH: int = 256
"""Largest training batch (``train --batch-size``, ``evaluate train-evaluator --batch-size``): one step of the default
backbone on 196-frame clips peaks at 12.6 GB resident at batch 512 on CPU, so 256 keeps a laptop out of swap."""


class UsageError(SimdiffError):
    """A command line argparse refused (unknown option, bad value)."""


_NEGATIVE_NUMBER = re.compile(r"^-(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$|^-(inf|infinity|nan)$", re.IGNORECASE)


class _RangeHelp(argparse.HelpFormatter):
    """Appends each checked option's accepted range to its help, unless the help already states it."""

    def _get_help_string(self, action: argparse.Action) -> str | None:
        text = super()._get_help_string(action)
        span = getattr(action.type, "span", None)
        if span and span not in (text or ""):
            return f"{text} (range {span})" if text else f"range {span}"
        return text


class Parser(argparse.ArgumentParser):
    """An argument parser whose errors are :class:`UsageError` lines (``simdiff: error: argument --x: …``), printed
    and turned into exit code 2 by :func:`simdiff.cli.main.main` like every other user error; ``--help`` shows
    every numeric option's range."""

    def __init__(self, *args, formatter_class: type[argparse.HelpFormatter] = argparse.HelpFormatter,
                 **kwargs) -> None:
        formatter = type(f"Range{formatter_class.__name__}", (_RangeHelp, formatter_class), {})
        super().__init__(*args, formatter_class=formatter, **kwargs)
        # "-1e3", "-inf", "-nan" are values, not options (argparse knows only "-1" and "-1.5"): no option starts so
        self._negative_number_matcher = _NEGATIVE_NUMBER

    def error(self, message: str) -> NoReturn:
        raise UsageError(f"{message} (see {self.prog} --help)")


def integer(lo: int, hi: int) -> Callable[[str], int]:
    """An argparse type: a whole number in ``lo..hi`` (decimal, no exponent)."""

    def parse(text: str) -> int:
        try:
            value = int(text.strip())
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not a whole number") from None
        if not lo <= value <= hi:
            raise argparse.ArgumentTypeError(f"{text} is outside {lo}..{hi}")
        return value

    parse.__name__ = "integer"
    parse.span = f"{lo}..{hi}"  # type: ignore[attr-defined]
    return parse


def real(lo: float = -math.inf, hi: float = math.inf, *, above: bool = False) -> Callable[[str], float]:
    """An argparse type: a finite number in ``[lo, hi]`` (``(lo, hi]`` with ``above``)."""

    left = "(" if above else "["
    span = f"{left}{lo:g}, {hi:g}]" if math.isfinite(hi) else (f"> {lo:g}" if above else f"≥ {lo:g}")
    if not math.isfinite(lo):
        span = f"≤ {hi:g}"

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
        if not math.isfinite(value):
            raise argparse.ArgumentTypeError(f"{text!r} is not a finite number")
        if value < lo or (above and value == lo) or value > hi:
            raise argparse.ArgumentTypeError(f"{text} is outside {span}")
        return value

    parse.__name__ = "real"
    parse.span = span  # type: ignore[attr-defined]
    return parse


SEED = integer(0, MAX_SEED)
"""``--seed``: numpy's and torch's seed range."""
WORKERS = integer(0, MAX_WORKERS)
"""``--workers N``: 0 = one per CPU."""
FPS_OPTION = real(MIN_FPS, MAX_FPS)
"""``--fps``: a frame rate in Hz."""


def add_environment_options(p: argparse.ArgumentParser | argparse._ArgumentGroup) -> None:
    """``--gravity G`` (m/s², default Earth) and ``--wind X Y`` (N) for commands that simulate or edit."""
    p.add_argument("--gravity", type=real(MIN_FORCED_GRAVITY, MAX_GRAVITY), default=-9.81,
                   help=f"vertical gravity g_z in m/s², {MIN_FORCED_GRAVITY:g}..{MAX_GRAVITY:g} (default -9.81)")
    p.add_argument("--wind", type=real(-MAX_FORCED_WIND, MAX_FORCED_WIND), nargs=2, default=(0.0, 0.0),
                   metavar=("X", "Y"),
                   help="wind force in N along HumanML3D +X (left) and +Z (forward) (default 0 0)")
