"""The ``--device`` option: a torch device this machine can run, or one line saying why not."""

from __future__ import annotations

import re
from typing import TYPE_CHECKING

from simdiff.errors import SimdiffError

if TYPE_CHECKING:
    import torch

_CUDA = re.compile(r"cuda(?::(\d+))?")


def torch_device(name: str, flag: str = "--device") -> "torch.device":
    """``cpu``, ``cuda`` / ``cuda:I`` (when this torch has CUDA and GPU I exists) or ``mps`` (when available).

    Raises:
        SimdiffError: any other name (``meta`` included), or a device this machine lacks; one line naming ``flag``.
    """
    import torch

    text = str(name).strip().lower()
    if text == "cpu":
        return torch.device("cpu")
    match = _CUDA.fullmatch(text)
    if match:
        if not torch.cuda.is_available():
            why = "this torch has no CUDA support" if not torch.backends.cuda.is_built() else "no CUDA GPU is visible"
            raise SimdiffError(f"{flag} {name}: {why}; use {flag} cpu")
        count = torch.cuda.device_count()
        index = int(match.group(1)) if match.group(1) is not None else 0
        if index >= count:
            raise SimdiffError(f"{flag} {name}: this machine has {count} CUDA device(s) (cuda:0..cuda:{count - 1})")
        return torch.device("cuda", index) if match.group(1) is not None else torch.device("cuda")
    if text == "mps":
        mps = getattr(torch.backends, "mps", None)
        if mps is None or not mps.is_available():
            raise SimdiffError(f"{flag} mps: this torch or machine has no MPS support; use {flag} cpu")
        return torch.device("mps")
    raise SimdiffError(f"{flag} {name!r}: unknown device; use cpu, cuda, cuda:N or mps")
