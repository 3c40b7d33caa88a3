"""Store a model folder's network weights as float16 (half the file: a GPU machine's carry, a smaller shipped model)
or back as float32.

Only the network's floating-point weights change precision; the feature Mean/Std (``normalizer.*``, (263,)) stay
float32, since generation and training compare and divide by them. :func:`simdiff.model.checkpoint.load_pretrained`
loads either into a float32 network, so a float16 folder samples and trains with its weights rounded to float16
(relative error ≤ 2⁻¹¹ ≈ 4.9e-4 each; values beyond ±65,504 are refused). The output records the recipe in
``precision.json``; ``sampling.json``, ``provenance.json`` and the model's README and recipes are copied unchanged.
"""

from __future__ import annotations

import os
from pathlib import Path

import torch

from simdiff.errors import SimdiffError
from simdiff.fsio import write_json
from simdiff.model.checkpoint import load_pretrained, save_derived
from simdiff.model.shards import weights_sha256

RECIPE_NAME = "precision.json"
DTYPES = {"float16": torch.float16, "float32": torch.float32}
COPIED = ("sampling.json", "provenance.json", "README.md", "deepening.json", "extrapolation.json")
"""Files of the source folder carried over byte for byte when present."""
KEPT_FLOAT32 = ("normalizer.",)


def convert_precision(model: str | os.PathLike[str], out: str | os.PathLike[str], dtype: str = "float16") -> Path:
    """Write ``out``: ``model`` with its network weights stored as ``dtype`` (``float16`` or ``float32``).

    Refused (one line) for another dtype, ``out`` equal to ``model``, or a weight too large for float16.
    """
    if dtype not in DTYPES:
        raise SimdiffError(f"precision must be one of {', '.join(DTYPES)}, got {dtype!r}")
    src, dst = Path(model), Path(out)
    if dst.resolve() == src.resolve():
        raise SimdiffError(f"{dst}: the output folder must differ from the model")
    network, config, extra = load_pretrained(src)
    if dtype == "float16":
        for key, value in network.state_dict().items():
            if value.is_floating_point() and bool(value.abs().max() > torch.finfo(torch.float16).max):
                raise SimdiffError(f"{src}: weight {key} exceeds float16's range (±65504); keep it float32")
    network.to(DTYPES[dtype])
    extra = {k: v if k.startswith(KEPT_FLOAT32) or not v.is_floating_point() else v.to(DTYPES[dtype])
             for k, v in extra.items()}  # float32 from load_pretrained
    save_derived(dst, network, config, extra, src, COPIED)
    write_json(dst / RECIPE_NAME, {"rule": f"network weights stored as {dtype}; normalizer.* float32",
                                   "dtype": dtype, "model": str(src), "model_sha256": weights_sha256(src)})
    return dst
