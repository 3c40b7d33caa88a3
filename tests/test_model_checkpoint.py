"""Weights files: the same tensors and metadata give the same bytes (hashes in recipes and provenance stay stable)."""

from __future__ import annotations

import json

import torch
from safetensors.torch import load, load_file

from simdiff.fsio import atomic_save_tensors, canonical_safetensors


def _with_metadata_order(keys: list[str]) -> bytes:
    """A safetensors blob whose ``__metadata__`` lists ``keys`` (values = key) in that order, as the library may."""
    header = {"__metadata__": {k: k for k in keys}, "w": {"dtype": "F32", "shape": [2], "data_offsets": [0, 8]}}
    text = json.dumps(header, separators=(",", ":")).encode()
    text += b" " * (-len(text) % 8)
    return len(text).to_bytes(8, "little") + text + torch.tensor([1.5, -2.0]).numpy().tobytes()


def test_metadata_order_does_not_change_the_bytes() -> None:
    a, b = _with_metadata_order(["format", "library", "x"]), _with_metadata_order(["x", "library", "format"])
    assert a != b
    ca, cb = canonical_safetensors(a), canonical_safetensors(b)
    assert ca == cb and len(ca) == len(a)
    assert torch.equal(load(ca)["w"], torch.tensor([1.5, -2.0]))


def test_saved_file_is_canonical_and_loads(tmp_path) -> None:
    tensors = {"b.weight": torch.arange(6, dtype=torch.float32).reshape(2, 3), "a.half": torch.ones(4, dtype=torch.float16)}
    meta = {"library": "simdiff", "format": "pt", "note": "x"}
    atomic_save_tensors(tensors, tmp_path / "w.safetensors", metadata=meta)
    blob = (tmp_path / "w.safetensors").read_bytes()
    assert canonical_safetensors(blob) == blob
    n = int.from_bytes(blob[:8], "little")
    assert list(json.loads(blob[8:8 + n])["__metadata__"]) == ["format", "library", "note"]
    back = load_file(str(tmp_path / "w.safetensors"))
    assert all(torch.equal(back[k], v) for k, v in tensors.items())


def test_blob_without_metadata_is_unchanged() -> None:
    from safetensors.torch import save

    blob = save({"w": torch.zeros(3)})
    assert canonical_safetensors(blob) == blob
