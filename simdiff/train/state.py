"""Training checkpoints without pickle: a step folder with weights, optimiser, EMA and the step.

Layout of ``<run>/checkpoints/step_000000100/``::

    model.safetensors      network weights (raw, not EMA) + normaliser
    config.json            ModelConfig
    state.safetensors      optimiser tensors (``optim.<param>.<name>``) and EMA (``ema.<param>``)
    state.json             step, optimiser param groups, scalar optimiser state, run config

The folder is written under a temporary name and renamed into place; ``<run>/checkpoints/latest``
(a one-line text file, replaced atomically) names the newest complete folder.
"""

from __future__ import annotations

import json
import os
import shutil
import tempfile
from pathlib import Path
from typing import Any

from safetensors.torch import load_file
from torch import Tensor

from simdiff.errors import SimdiffError
from simdiff.fsio import atomic_save_tensors
from simdiff.model.checkpoint import atomic_write_json
from simdiff.model.optimizer_state import optimizer_from_flat, optimizer_to_flat

LATEST = "latest"


def write_checkpoint(run_dir: Path, step: int, model_tensors: dict[str, Tensor], model_config: dict[str, Any],
                     optimizer_state: dict[str, Any], ema_state: dict[str, Tensor] | None, run_config: dict[str, Any],
                     keep: int = 2) -> Path:
    """Write the step folder atomically, point ``latest`` at it, and prune old folders."""
    root = run_dir / "checkpoints"
    root.mkdir(parents=True, exist_ok=True)
    final = root / f"step_{step:09d}"
    tmp = Path(tempfile.mkdtemp(prefix=".tmp_step_", dir=root))
    try:
        atomic_save_tensors(model_tensors, tmp / "model.safetensors")
        atomic_write_json(model_config, tmp / "config.json")
        tensors, meta = optimizer_to_flat(optimizer_state)
        if ema_state is not None:
            tensors.update({f"ema.{k}": v for k, v in ema_state.items()})
        atomic_save_tensors(tensors, tmp / "state.safetensors")
        atomic_write_json({"step": step, "optimizer": meta, "run": run_config, "ema": ema_state is not None}, tmp / "state.json")
        if final.exists():
            shutil.rmtree(final)
        os.replace(tmp, final)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    _atomic_text(root / LATEST, final.name)
    folders = sorted(p for p in root.glob("step_*") if p.is_dir())
    for old in folders[: max(0, len(folders) - max(1, keep))]:
        shutil.rmtree(old, ignore_errors=True)
    return final


def _atomic_text(path: Path, text: str) -> None:
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", dir=path.parent)
    with os.fdopen(fd, "w") as f:
        f.write(text + "\n")
    os.replace(tmp, path)


def latest_checkpoint(run_dir: Path) -> Path | None:
    """The newest complete step folder of a run, or None."""
    pointer = run_dir / "checkpoints" / LATEST
    if not pointer.is_file():
        return None
    folder = run_dir / "checkpoints" / pointer.read_text().strip()
    return folder if (folder / "state.json").is_file() else None


def read_checkpoint(folder: Path) -> tuple[int, dict[str, Tensor], dict[str, Any], dict[str, Tensor] | None, dict[str, Any]]:
    """Return ``(step, model_tensors, optimizer_state, ema_state, run_config)`` of a step folder."""
    try:
        meta = json.loads((folder / "state.json").read_text())
        state_tensors = load_file(str(folder / "state.safetensors"))
        model = load_file(str(folder / "model.safetensors"))
    except FileNotFoundError as exc:
        raise SimdiffError(f"incomplete checkpoint {folder}: {exc.filename} missing") from None
    ema = {k[4:]: v for k, v in state_tensors.items() if k.startswith("ema.")} if meta.get("ema") else None
    return int(meta["step"]), model, optimizer_from_flat(state_tensors, meta["optimizer"]), ema, meta["run"]
