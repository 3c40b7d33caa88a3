"""Weights I/O: ``model.safetensors`` + ``config.json`` (no pickle), and the official MDM loader."""

from __future__ import annotations

import dataclasses
import json
import os
import tempfile
from pathlib import Path
from typing import Any, Mapping

import torch
from safetensors.torch import load_file
from torch import Tensor, nn

from simdiff.errors import SimdiffError
from simdiff.fsio import atomic_save_tensors, read_config_json
from simdiff.model.backbone import MDMBackbone
from simdiff.model.config import BackboneConfig, ModelConfig, check_model_config, config_from_dict
from simdiff.model.simdiff_net import SimDiffNet

WEIGHTS_NAME = "model.safetensors"
CONFIG_NAME = "config.json"


def build_network(config: ModelConfig) -> MDMBackbone | SimDiffNet:
    """The backbone alone, or SimDiff when ``config.sim`` is set (float32, on CPU)."""
    if config.sim is None:
        return MDMBackbone(config.backbone)
    return SimDiffNet(config.backbone, config.sim)


def _atomic(path: Path, write: Any) -> None:
    """Call ``write(tmp_path)`` then ``os.replace`` it onto ``path`` (same folder, so atomic)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    os.close(fd)
    try:
        write(tmp)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def atomic_write_json(data: Any, path: str | os.PathLike[str]) -> None:
    """Write JSON atomically."""

    def write(tmp: str) -> None:
        with open(tmp, "w", encoding="utf-8") as f:
            json.dump(data, f, indent=2, sort_keys=True)
            f.write("\n")

    _atomic(Path(path), write)


def save_pretrained(folder: str | os.PathLike[str], network: nn.Module, config: ModelConfig,
                    extra: Mapping[str, Tensor] | None = None) -> None:
    """Write ``folder/model.safetensors`` (network weights + ``extra`` tensors) and ``folder/config.json``.

    ``extra`` holds non-network tensors such as the feature ``normalizer.mean``/``normalizer.std`` (263,).
    The weights are written before the config, each atomically.
    """
    folder = Path(folder)
    tensors = dict(network.state_dict())
    for key, value in (extra or {}).items():
        tensors[key] = value
    atomic_save_tensors(tensors, folder / WEIGHTS_NAME, metadata={"format": "pt", "library": "simdiff"})
    atomic_write_json(dataclasses.asdict(config), folder / CONFIG_NAME)


def save_derived(dst: str | os.PathLike[str], network: nn.Module, config: ModelConfig, extra: Mapping[str, Tensor],
                 src: str | os.PathLike[str], copied: tuple[str, ...]) -> Path:
    """Write a model made from folder ``src`` (weights and config via :func:`save_pretrained`) into ``dst``, with
    ``src``'s files named in ``copied`` (e.g. ``sampling.json``) carried over byte for byte when present."""
    from simdiff.fsio import write_bytes

    dst, src = Path(dst), Path(src)
    dst.mkdir(parents=True, exist_ok=True)
    save_pretrained(dst, network, config, extra)
    for name in copied:
        if (src / name).is_file():
            write_bytes(dst / name, (src / name).read_bytes())
    return dst


def read_config(folder: str | os.PathLike[str]) -> ModelConfig:
    """Read ``folder/config.json`` into a :class:`ModelConfig`."""
    path = Path(folder) / CONFIG_NAME
    if not path.is_file():
        raise SimdiffError(f"{path}: no such file (expected a model folder with {CONFIG_NAME} and {WEIGHTS_NAME})")
    data = read_config_json(path)
    return check_model_config(config_from_dict(data, ModelConfig, str(path)), str(path))


def load_pretrained(folder: str | os.PathLike[str], device: torch.device | str = "cpu") -> tuple[nn.Module, ModelConfig, dict[str, Tensor]]:
    """Load a model folder (whole ``model.safetensors`` or shards with an index; weights stored as float32 or
    float16, :mod:`simdiff.model.precision`); returns ``(network, config, extra_tensors)``, all float32, with the
    network on ``device``."""
    config = read_config(folder)
    path = Path(folder) / WEIGHTS_NAME
    from simdiff.model.shards import INDEX_NAME, load_sharded

    if path.is_file():
        tensors = read_tensors(path)
    elif (Path(folder) / INDEX_NAME).is_file():
        try:
            tensors = load_sharded(folder)
        except SimdiffError:
            raise
        except Exception as exc:  # a corrupt shard: one line naming the folder
            raise SimdiffError(f"{Path(folder) / INDEX_NAME}: cannot read the weight shards ({_first_line(exc)})") from None
    else:
        raise SimdiffError(f"{path}: no such file")
    network = build_network(config)
    check_weights(folder, network.state_dict(), tensors)
    check_finite(path, tensors)
    own = set(network.state_dict())
    extra = {k: v.float() if v.is_floating_point() else v for k, v in tensors.items() if k not in own}
    network.load_state_dict({k: v for k, v in tensors.items() if k in own}, strict=True)
    return network.to(device), config, extra


def _first_line(exc: BaseException) -> str:
    text = str(exc).strip()
    return text.splitlines()[0] if text else type(exc).__name__


def read_tensors(path: str | os.PathLike[str]) -> dict[str, Tensor]:
    """All tensors of safetensors file ``path`` on the CPU.

    Raises:
        SimdiffError: the file is missing, truncated or not safetensors (a header claiming more bytes than the file
            holds included); one line naming the file.
    """
    try:
        return load_file(str(path), device="cpu")
    except Exception as exc:  # safetensors raises its own SafetensorError, OSError, or MemoryError on a huge header
        raise SimdiffError(f"{Path(path).parent}: cannot load model: {Path(path).name} is not a readable safetensors "
                           f"file ({_first_line(exc)})") from None


def check_finite(path: str | os.PathLike[str], tensors: Mapping[str, Tensor]) -> None:
    """Refuse weights holding NaN or infinite values (sampling would give nothing but NaN)."""
    for key, value in tensors.items():
        if value.is_floating_point() and not bool(torch.isfinite(value).all()):
            what = "NaN" if bool(torch.isnan(value).any()) else "infinite"
            raise SimdiffError(f"{path}: weight {key} has {what} values")


EXTRA_PREFIXES: tuple[str, ...] = ("normalizer.",)
"""Tensors a model file holds beside the network's weights (the feature Mean/Std)."""


def check_weights(folder: str | os.PathLike[str], expected: dict[str, Tensor], tensors: dict[str, Tensor]) -> None:
    """Refuse weights that do not match ``config.json``'s network: a tensor missing, one left over, or one of another
    shape (a config saying 2 layers beside 8-layer weights would otherwise load and generate nonsense)."""
    where = f"{folder}: config.json does not match {WEIGHTS_NAME}"
    missing = [k for k in expected if k not in tensors]
    if missing:
        raise SimdiffError(f"{where}: {len(missing)} weight(s) the config describes are absent, e.g. {missing[0]!r}")
    extra = [k for k in tensors if k not in expected and not k.startswith(EXTRA_PREFIXES)]
    if extra:
        raise SimdiffError(f"{where}: {len(extra)} weight(s) the config does not describe, e.g. {extra[0]!r}")
    for k, v in expected.items():
        if tuple(tensors[k].shape) != tuple(v.shape):
            raise SimdiffError(f"{where}: {k!r} is {tuple(tensors[k].shape)} in the file, {tuple(v.shape)} by the "
                               "config")


def export_backbone(src: str | os.PathLike[str], dst: str | os.PathLike[str]) -> Path:
    """Write the frozen backbone of SimDiff model folder ``src`` as a backbone-only model folder ``dst``.

    The weights are the backbone's own (bit-identical), with the feature Mean/Std; the config is
    ``src``'s without its ``sim`` part; ``provenance.json`` keeps the backbone's records. The MDM rows
    of an evaluation then run the very backbone the shipped SimDiff model was trained on.
    """
    from simdiff.model.provenance import Provenance, read_provenance, write_provenance

    network, config, extra = load_pretrained(src)
    if not isinstance(network, SimDiffNet):
        raise SimdiffError(f"{src}: already a backbone-only model (config.json has no 'sim' part)")
    out = Path(dst)
    save_pretrained(out, network.backbone, dataclasses.replace(config, sim=None),
                    {k: v for k, v in extra.items() if k.startswith("normalizer.")})
    prov = read_provenance(src)
    if prov is not None:
        write_provenance(out, Provenance([p for p in prov.trained_on if p.what == "backbone"]))
    return out


# --- the official MDM checkpoint -------------------------------------------------------------

_IGNORED_PREFIXES = ("clip_model.",)
_IGNORED_KEYS = ("sequence_pos_encoder.pe", "embed_timestep.sequence_pos_encoder.pe")


def mdm_backbone_config(state_dict: Mapping[str, Tensor], num_heads: int = 4, **overrides: Any) -> BackboneConfig:
    """Infer a :class:`BackboneConfig` from an MDM state dict's shapes (heads cannot be inferred)."""
    try:
        latent, nfeats = state_dict["input_process.poseEmbedding.weight"].shape
        text_dim = state_dict["embed_text.weight"].shape[1]
        ff = state_dict["seqTransEncoder.layers.0.linear1.weight"].shape[0]
    except KeyError as exc:
        raise SimdiffError(f"not an MDM text-to-motion checkpoint: missing {exc.args[0]}") from None
    layers = 1 + max(int(k.split(".")[2]) for k in state_dict if k.startswith("seqTransEncoder.layers."))
    values: dict[str, Any] = dict(nfeats=int(nfeats), latent_dim=int(latent), num_layers=layers, num_heads=num_heads,
                                  ff_size=int(ff), text_dim=int(text_dim), dropout=0.1, activation="gelu")
    values.update(overrides)
    return BackboneConfig(**values)


def mdm_state_dict(raw: Mapping[str, Any]) -> dict[str, Tensor]:
    """Select the model weights from an MDM checkpoint dict.

    Accepts a flat state dict or an EMA checkpoint ``{'model': sd, 'model_avg': sd}`` (the
    averaged weights are used). Drops ``clip_model.*`` and the PE buffers.
    """
    if "model_avg" in raw and isinstance(raw["model_avg"], Mapping):
        raw = raw["model_avg"]
    elif "model" in raw and isinstance(raw["model"], Mapping):
        raw = raw["model"]
    return {
        k: v for k, v in raw.items()
        if not k.startswith(_IGNORED_PREFIXES) and k not in _IGNORED_KEYS
    }


def load_mdm_state_dict(backbone: MDMBackbone, raw: Mapping[str, Any]) -> None:
    """Load official MDM weights into ``backbone`` (names and shapes must match exactly)."""
    state = mdm_state_dict(raw)
    own = backbone.state_dict()
    missing = sorted(set(own) - set(state))
    unexpected = sorted(set(state) - set(own))
    if missing or unexpected:
        raise SimdiffError(f"MDM checkpoint mismatch: missing {missing[:3]}, unexpected {unexpected[:3]}")
    for key, value in state.items():
        if tuple(value.shape) != tuple(own[key].shape):
            raise SimdiffError(f"MDM checkpoint: {key} has shape {tuple(value.shape)}, expected {tuple(own[key].shape)}")
    backbone.load_state_dict({k: v.float() for k, v in state.items()}, strict=True)


def load_mdm_checkpoint(path: str | os.PathLike[str], num_heads: int = 4) -> MDMBackbone:
    """Build and load an :class:`MDMBackbone` from an official MDM ``model*.pt`` file.

    The file is read with ``torch.load(weights_only=True)`` (no arbitrary unpickling). The
    official model uses CLIP ViT-B/32 text vectors (``text_dim`` 512).
    """
    path = Path(path)
    if not path.is_file():
        raise SimdiffError(f"{path}: no such MDM checkpoint file")
    raw = torch.load(str(path), map_location="cpu", weights_only=True)
    state = mdm_state_dict(raw)
    backbone = MDMBackbone(mdm_backbone_config(state, num_heads=num_heads))
    load_mdm_state_dict(backbone, state)
    return backbone
