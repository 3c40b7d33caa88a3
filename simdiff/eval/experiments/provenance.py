"""Where a report came from: command, git commit, seed, machine (with torch's view of it), time."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import torch

from simdiff.runinfo import now, run_info

__all__ = ["folder_stamp", "load_average", "now", "provenance"]


def load_average() -> list[float] | None:
    """1-, 5- and 15-minute load averages (None where the platform has none)."""
    try:
        return [round(x, 2) for x in os.getloadavg()]
    except (AttributeError, OSError):
        return None


def provenance(seed: int, device: str, command: list[str] | None = None) -> dict[str, Any]:
    """:func:`simdiff.runinfo.run_info` plus the working folder, seed, torch version, threads and device."""
    info = run_info(command)
    dev = torch.device(device)
    info["machine"].update({
        "torch": torch.__version__, "torch_threads": torch.get_num_threads(), "device": str(dev),
        "device_name": torch.cuda.get_device_name(dev) if dev.type == "cuda" else "cpu",
        "load_avg_start": load_average()})
    return {**info, "cwd": os.getcwd(), "seed": seed}


def folder_stamp(path: str) -> dict[str, Any]:
    """A folder as (absolute path, size and mtime of its weights): re-measure when a model is retrained."""
    p = Path(path).expanduser().resolve() if path else Path()
    out: dict[str, Any] = {"path": str(p)}
    for name in ("model.safetensors", "finest.tar"):
        f = p / name if p.is_dir() else p
        if f.is_file():
            out.update(size=f.stat().st_size, mtime_ns=f.stat().st_mtime_ns)
            break
    return out
