"""The shipped default model: where it lives and how to load it.

The default model is a SimDiff network (frozen backbone + continuous-φ Sim Encoder and Motion
Adapters) stored as ``model.safetensors`` + ``config.json`` in ``simdiff/assets/default_model/``.
``SIMDIFF_MODEL`` (environment variable) or an explicit folder overrides it.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING

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
    """Load the default (or given) model folder as a :class:`~simdiff.model.generator.MotionGenerator`.

    Raises:
        SimdiffError: the folder or its files are missing or unreadable (one line, names the path).
    """
    from simdiff.model.generator import MotionGenerator

    folder = check_model_dir(model)
    try:
        return MotionGenerator.load(folder, device=device, load_text=load_text)
    except SimdiffError:
        raise
    except Exception as exc:  # corrupt safetensors / JSON: one line naming the folder
        raise SimdiffError(f"{folder}: cannot load model: {type(exc).__name__}: {str(exc).splitlines()[0] if str(exc) else ''}") from None


SAMPLING_NAME = "sampling.json"
"""Optional file beside ``config.json`` with the model's recommended sampling settings."""
SAMPLING_KEYS: dict[str, type] = {"alpha": float, "guidance": float, "steps": int, "sampler": str, "foot_lock": float,
                                  "env_guidance": float, "env_guidance_fallback": float, "anchor": str,
                                  "anchor_alpha": float, "anchor_t_max": int, "edit_t": int,
                                  "ballistic": float, "eta": float}


def sampling_defaults(model: str | os.PathLike[str] | None = None) -> dict[str, float | int | str]:
    """Recommended sampling settings stored with a model (``sampling.json``), or ``{}`` when it has none.

    The file is a JSON object with any of ``alpha`` (adapter strength), ``guidance``, ``steps``,
    ``sampler``, ``foot_lock`` (:mod:`simdiff.motion.foot_lock`'s strength), ``env_guidance``
    (:mod:`simdiff.diffusion.guidance`'s s_e), ``env_guidance_fallback`` (the s_e for samples that float or glide),
    ``anchor`` (its text-guidance anchor), ``anchor_alpha`` (the backbone or reference anchor's adapter strength) and
    ``anchor_t_max`` (that anchor only at timesteps ≤ it), ``edit_t`` (the edit anchor's last timestep at Earth),
    ``ballistic`` (:mod:`simdiff.motion.ballistic`'s strength) and ``eta`` (DDIM's η in [0, 1]), e.g.
    ``{"alpha": 0.8}``;
    values the user gives on the command line win.

    Raises:
        SimdiffError: the file is not valid JSON or holds an unknown key or a value of the wrong type.
    """
    import json

    path = default_model_dir(model) / SAMPLING_NAME
    if not path.is_file():
        return {}
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        raise SimdiffError(f"{path}: cannot read sampling defaults: {str(exc).splitlines()[0]}") from None
    if not isinstance(data, dict):
        raise SimdiffError(f"{path}: expected a JSON object such as {{\"alpha\": 1.0}}")
    out: dict[str, float | int | str] = {}
    for key, value in data.items():
        kind = SAMPLING_KEYS.get(key)
        if kind is None:
            raise SimdiffError(f"{path}: unknown key {key!r}; allowed: {', '.join(SAMPLING_KEYS)}")
        ok = isinstance(value, str) if kind is str else isinstance(value, (int, float)) and not isinstance(value, bool)
        if not ok or (kind is int and float(value) != int(value)):
            raise SimdiffError(f"{path}: {key} must be {kind.__name__}, got {value!r}")
        out[key] = kind(value)
    return out
