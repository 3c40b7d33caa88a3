"""User-facing errors: the CLI prints these as a single line, never a traceback."""


class SimdiffError(Exception):
    """An error caused by bad user input (a file, a value, a missing weight).

    The message must name the offending value or file and fit on one line.
    """


class MotionFormatError(SimdiffError):
    """A motion file that cannot be parsed; the message names file and line."""

    def __init__(self, path: object, message: str, line: int | None = None) -> None:
        where = f"{path}:{line}" if line is not None else f"{path}"
        super().__init__(f"{where}: {message}")
        self.path = path
        self.line = line


class NonFiniteResult(SimdiffError):
    """A computation produced NaN or infinite values (extreme settings); nothing of it is written or shown."""


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised like Ctrl-C so that the same clean-up runs (temporary files removed, workers stopped)."""
