"""Extrapolate a fine-tune in weight space (task arithmetic): backbone θ = θ_model + λ·(θ_model − θ_parent).

``model`` must be ``parent`` fine-tuned (same architecture and feature Mean/Std); λ 0 copies ``model``, λ > 0 goes
further in the direction the fine-tune moved the weights (a jump-weighted fine-tune extrapolated at λ 1
doubled its gain in Earth jumps on val), λ in [−1, 0) goes back towards
``parent``. Only the backbone changes: a
SimDiff model's Sim Encoder and Motion Adapters, its normaliser, config and ``sampling.json`` are ``model``'s.
The output folder records the recipe in ``extrapolation.json`` and both models' training data in ``provenance.json``.
"""

from __future__ import annotations

import dataclasses
import math
import os
from pathlib import Path

import torch
from torch import nn

from simdiff.errors import SimdiffError
from simdiff.fsio import write_json
from simdiff.model.checkpoint import load_pretrained, save_derived
from simdiff.model.shards import weights_sha256
from simdiff.model.simdiff_net import SimDiffNet

RECIPE_NAME = "extrapolation.json"
COPIED = ("sampling.json",)
"""Files of ``model``'s folder carried over unchanged (generation settings belong to the model)."""


def _backbone(network: nn.Module) -> nn.Module:
    return network.backbone if isinstance(network, SimDiffNet) else network


def extrapolate_backbone(model: str | os.PathLike[str], parent: str | os.PathLike[str], lam: float,
                         out: str | os.PathLike[str]) -> Path:
    """Write ``out``: ``model`` with its backbone weights moved to θ_model + lam·(θ_model − θ_parent).

    ``parent`` may be a SimDiff or a backbone-only folder; only its backbone is read. Refused (one line) when the
    backbones' architectures (the attention mask aside) or the feature Mean/Std differ, or lam is not finite.
    """
    lam = float(lam)
    if not math.isfinite(lam):
        raise SimdiffError(f"extrapolation factor must be a finite number, got {lam}")
    src, par, dst = Path(model), Path(parent), Path(out)
    if dst.resolve() in (src.resolve(), par.resolve()):
        raise SimdiffError(f"{dst}: the output folder must differ from the model and the parent")
    network, config, extra = load_pretrained(src)
    parent_net, parent_config, parent_extra = load_pretrained(par)
    mine = dataclasses.replace(config.backbone, mask_frames=False)
    theirs = dataclasses.replace(parent_config.backbone, mask_frames=False)
    if mine != theirs:
        field = next(f.name for f in dataclasses.fields(mine) if getattr(mine, f.name) != getattr(theirs, f.name))
        raise SimdiffError(f"{par}: backbone {field} is {getattr(theirs, field)}, the model's is "
                           f"{getattr(mine, field)}; extrapolation needs the same architecture")
    for key in ("normalizer.mean", "normalizer.std"):
        a, b = extra.get(key), parent_extra.get(key)
        if a is None or b is None or not torch.equal(a, b):
            raise SimdiffError(f"{par}: its {key} differs from the model's; extrapolation needs the same features")
    backbone, start = _backbone(network), _backbone(parent_net).state_dict()
    state = backbone.state_dict()
    with torch.no_grad():
        moved = {k: (v + lam * (v - start[k])).to(v.dtype) if v.is_floating_point() else v for k, v in state.items()}
    backbone.load_state_dict(moved)
    save_derived(dst, network, config, extra, src, COPIED)
    _write_provenance(src, par, dst)
    digest = {name: weights_sha256(folder)
              for name, folder in (("model", src), ("parent", par))}
    write_json(dst / RECIPE_NAME, {
        "rule": "backbone = model + lambda * (model - parent); everything else the model's",
        "lambda": lam, "model": str(src), "model_sha256": digest["model"],
        "parent": str(par), "parent_sha256": digest["parent"]})
    return dst


def read_recipe(model_dir: str | os.PathLike[str]) -> dict | None:
    """``model_dir/extrapolation.json`` (None when absent); invalid JSON is one :class:`SimdiffError` line naming it."""
    import json

    path = Path(model_dir) / RECIPE_NAME
    if not path.is_file():
        return None
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise SimdiffError(f"{path}: not valid JSON ({exc})") from None
    if not isinstance(data, dict) or not isinstance(data.get("lambda"), (int, float)):
        raise SimdiffError(f"{path}: expected an object with a numeric 'lambda'")
    return data


def _write_provenance(src: Path, par: Path, dst: Path) -> None:
    """The model's records, then the parent's backbone records it does not already hold (the licence over all)."""
    from simdiff.model.provenance import Provenance, read_provenance, write_provenance

    mine, theirs = read_provenance(src), read_provenance(par)
    if mine is None and theirs is None:
        return
    parts = list(mine.trained_on) if mine is not None else []
    for p in theirs.trained_on if theirs is not None else []:
        if p.what == "backbone" and p not in parts:
            parts.append(p)
    write_provenance(dst, Provenance(parts))
