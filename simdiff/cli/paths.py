"""Checks on the folders a command reads and writes."""

from __future__ import annotations

import os
from pathlib import Path

from simdiff.errors import SimdiffError


def check_separate(out: str | os.PathLike[str], **inputs: str | os.PathLike[str] | None) -> None:
    """Refuse an output folder that is an input folder, lies inside one, or holds one.

    ``inputs`` maps option names (``model``, ``parent``; an underscore is shown as ``-``; an upper-case name such as
    ``CORPUS`` is a positional argument) to the folders a command reads; None values are skipped. Writing into an
    input would overwrite or wipe the very files being read.

    Raises:
        SimdiffError: one line naming ``--out`` and the input option.
    """
    target = Path(out).expanduser().resolve()
    for name, value in inputs.items():
        if value is None:
            continue
        source = Path(value).expanduser().resolve()
        flag = f"the {name.lower()}" if name.isupper() else f"--{name.replace('_', '-')}"  # upper case: a positional
        if target == source:
            raise SimdiffError(f"--out {out} is the same folder as {flag} {value}; choose another output folder")
        if source in target.parents:
            raise SimdiffError(f"--out {out} lies inside {flag} {value}; choose a folder outside it")
        if target in source.parents:
            raise SimdiffError(f"--out {out} holds {flag} {value}; choose a folder that does not contain it")
