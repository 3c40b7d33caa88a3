"""Upper bounds shared by the readers, the worker pools and the command line (no imports: the CLI's ``--help``
reads them without loading numpy, torch or scipy)."""

MIN_FPS: float = 1.0
"""Lowest frame rate (Hz) a motion file may declare or a caller may ask for: below it a few frames resample to
thousands of 20 fps frames (and a rate near zero overflows)."""
MAX_FPS: float = 1000.0
"""Highest frame rate (Hz) a motion file may declare or a caller may ask for (mocap runs at 30-480 Hz)."""
MAX_WORKERS: int = 64
"""Most worker processes (or concurrent Ray tasks) a pool runs."""
MAX_COORD: float = 10_000.0
"""Largest absolute joint coordinate (metres, 10 km) a motion may hold: beyond it the data is not a body moving near
the origin, and the metrics, renders and fits it would feed are meaningless (or overflow)."""
