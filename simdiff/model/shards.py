"""Weights split into safetensors shards of at most N bytes, with a Hugging Face-style index.

Layout (``folder/``)::

    model-00001-of-00003.safetensors ...   the tensors, greedily packed in name order
    model.safetensors.index.json           {"metadata": {"total_size": bytes}, "weight_map": {name: file}}

:func:`simdiff.model.checkpoint.load_pretrained` reads a folder with this index when it has no
``model.safetensors``, so a sharded model folder loads like a whole one (bit-exact).
"""

from __future__ import annotations

import hashlib
import json
import shutil
from pathlib import Path
from typing import Mapping

from safetensors.torch import load_file
from torch import Tensor

from simdiff.errors import SimdiffError
from simdiff.fsio import write_json

INDEX_NAME = "model.safetensors.index.json"
HEADER_SLACK = 1024
"""Bytes kept free per shard for the safetensors header, plus :data:`PER_TENSOR` per tensor."""
PER_TENSOR = 256


def _nbytes(t: Tensor) -> int:
    return t.numel() * t.element_size()


def shard_tensors(tensors: Mapping[str, Tensor], folder: str | Path, max_bytes: int) -> list[str]:
    """Write ``tensors`` into ``folder`` as shards of at most ``max_bytes`` each (file size); returns file names."""
    from simdiff.fsio import atomic_save_tensors

    folder = Path(folder)
    budget = max_bytes - HEADER_SLACK
    if budget <= 0:
        raise SimdiffError(f"shard size {max_bytes} bytes is too small (needs more than {HEADER_SLACK})")
    groups: list[list[str]] = [[]]
    size = 0
    for name in sorted(tensors):
        n = _nbytes(tensors[name]) + PER_TENSOR + len(name)
        if n > budget:
            raise SimdiffError(f"tensor {name} ({n} bytes) does not fit in a {max_bytes}-byte shard")
        if groups[-1] and size + n > budget:
            groups.append([])
            size = 0
        groups[-1].append(name)
        size += n
    files = [f"model-{i + 1:05d}-of-{len(groups):05d}.safetensors" for i in range(len(groups))]
    weight_map: dict[str, str] = {}
    for file, names in zip(files, groups):
        atomic_save_tensors({k: tensors[k] for k in names}, folder / file, metadata={"format": "pt", "library": "simdiff"})
        weight_map.update({k: file for k in names})
        if (folder / file).stat().st_size > max_bytes:  # the header estimate was wrong: never ship an oversize shard
            raise SimdiffError(f"{folder / file}: {(folder / file).stat().st_size} bytes, over the {max_bytes}-byte shard size")
    total = sum(_nbytes(t) for t in tensors.values())
    write_json(folder / INDEX_NAME, {"metadata": {"total_size": total}, "weight_map": weight_map})
    for path in folder.glob("model-*-of-*.safetensors"):  # shards of an older, different split
        if path.name not in files:
            path.unlink()
    return files


def _read_index(folder: Path) -> tuple[dict[str, str], list[Path]]:
    """A sharded folder's weight map (tensor name → shard file) and its shard paths in name order, each checked to
    exist (one :class:`SimdiffError` line otherwise)."""
    index_path = folder / INDEX_NAME
    try:
        weight_map: dict[str, str] = json.loads(index_path.read_text(encoding="utf-8"))["weight_map"]
        files = sorted(set(weight_map.values()))
    except (OSError, ValueError, KeyError, TypeError, AttributeError) as exc:
        raise SimdiffError(f"{index_path}: cannot read shard index ({type(exc).__name__})") from None
    paths = [folder / file for file in files]
    for path in paths:
        if not path.is_file():
            raise SimdiffError(f"{path}: shard named in {INDEX_NAME} is missing")
    return weight_map, paths


def load_sharded(folder: str | Path, device: str = "cpu") -> dict[str, Tensor]:
    """All tensors of a sharded folder (checks every indexed name is present in its shard)."""
    folder = Path(folder)
    weight_map, paths = _read_index(folder)
    tensors: dict[str, Tensor] = {}
    for path in paths:
        tensors.update(load_file(str(path), device=device))
    missing = sorted(set(weight_map) - set(tensors))
    if missing:
        raise SimdiffError(f"{folder}: tensors {missing[:3]} named in {INDEX_NAME} are not in their shards")
    return {k: tensors[k] for k in weight_map}


def shard_model_folder(model: str | Path, out: str | Path, max_bytes: int) -> list[str]:
    """Copy model folder ``model`` to ``out`` with its weights sharded (config and side files copied); returns shard names."""
    model, out = Path(model), Path(out)
    weights = model / "model.safetensors"
    if not weights.is_file():
        raise SimdiffError(f"{weights}: no such file")
    out.mkdir(parents=True, exist_ok=True)
    files = shard_tensors(load_file(str(weights)), out, max_bytes)
    for side in sorted(model.iterdir()):
        if side.is_file() and side.name != "model.safetensors":
            shutil.copyfile(side, out / side.name)
    return files


def weights_sha256(folder: str | Path) -> str:
    """sha256 naming a model folder's weights: of ``model.safetensors`` when present, else of a sharded folder's
    index followed by its shards' own sha256 in name order (one :class:`SimdiffError` line when it has neither)."""
    folder = Path(folder)
    whole = folder / "model.safetensors"
    if whole.is_file():
        return hashlib.sha256(whole.read_bytes()).hexdigest()
    if not (folder / INDEX_NAME).is_file():
        raise SimdiffError(f"{folder}: no model.safetensors or {INDEX_NAME}")
    _, paths = _read_index(folder)
    h = hashlib.sha256((folder / INDEX_NAME).read_bytes())
    for path in paths:
        h.update(path.name.encode() + b"\0" + hashlib.sha256(path.read_bytes()).digest())
    return h.hexdigest()
