"""The shipped default model: where it lives, how to load it and its sampling settings.

The default model is a SimDiff network (frozen backbone + continuous-φ Sim Encoder and Motion
Adapters) stored as ``model.safetensors`` + ``config.json`` in ``simdiff/assets/default_model/``.
``SIMDIFF_MODEL`` (environment variable) or an explicit folder overrides it.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING

from simdiff.diffusion.config import SamplingConfig
from simdiff.errors import SimdiffError

if TYPE_CHECKING:  # torch is imported only when a model is loaded (keeps errors and --help fast)
    import torch

DEFAULT_MODEL_DIR = Path(__file__).resolve().parent.parent / "assets" / "default_model"
"""Folder of the shipped weights inside the installed package."""

MODEL_ENV_VAR = "SIMDIFF_MODEL"


def default_model_dir(model: str | os.PathLike[str] | None = None) -> Path:
    """The model folder to use: ``model`` if given, else ``$SIMDIFF_MODEL``, else the shipped one."""
    if model is not None:
        return Path(model)
    env = os.environ.get(MODEL_ENV_VAR)
    return Path(env) if env else DEFAULT_MODEL_DIR


def check_model_dir(model: str | os.PathLike[str] | None = None) -> Path:
    """The model folder (see :func:`default_model_dir`) after checking its two files exist.

    Raises:
        SimdiffError: a file is missing; for the shipped default, says that no default model is installed.
    """
    folder = default_model_dir(model)
    for name in ("config.json", "model.safetensors"):
        if name == "model.safetensors" and (folder / "model.safetensors.index.json").is_file():
            continue  # sharded weights
        if not (folder / name).is_file():
            if model is None and not os.environ.get(MODEL_ENV_VAR):
                raise SimdiffError(f"no default model installed ({folder / name} is missing); "
                                   f"pass --model DIR or set {MODEL_ENV_VAR} to a model folder")
            raise SimdiffError(f"{folder / name}: model file not found (set {MODEL_ENV_VAR} or pass --model)")
    return folder


def load_default(model: str | os.PathLike[str] | None = None, device: "torch.device | str" = "cpu",
                 load_text: bool = True):  # -> MotionGenerator (import kept lazy: torch-heavy)
    """Load the default (or given) model folder as a :class:`~simdiff.inference.generator.MotionGenerator`.

    Raises:
        SimdiffError: the folder or its files are missing or unreadable (one line, names the path).
    """
    from simdiff.inference.generator import MotionGenerator

    folder = check_model_dir(model)
    try:
        return MotionGenerator.load(folder, device=device, load_text=load_text)
    except SimdiffError:
        raise
    except Exception as exc:  # corrupt safetensors / JSON: one line naming the folder
        raise SimdiffError(f"{folder}: cannot load model: {type(exc).__name__}: {str(exc).splitlines()[0] if str(exc) else ''}") from None


SAMPLING_NAME = "sampling.json"
"""File beside ``config.json`` with the model's sampling settings (:class:`SamplingConfig`'s fields)."""


def sampling_config(model: str | os.PathLike[str] | None = None) -> SamplingConfig:
    """The model's sampling settings (``sampling.json``; :class:`SamplingConfig`'s defaults for the keys it lacks,
    or without the file). Reads one small JSON file: no torch.

    Raises:
        SimdiffError: the file is not a JSON object, or holds an unknown key or a bad value (one line).
    """
    path = default_model_dir(model) / SAMPLING_NAME
    return SamplingConfig.read(path) if path.is_file() else SamplingConfig()
