"""Z-normalisation of HumanML3D 263-dim features, and the dataset's grouped Mean/Std.

``x_norm = (x - mean) / std`` over the last axis; padding is zeros in normalised space.
"""

from __future__ import annotations

import warnings
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import TypeVar

import numpy as np
import torch

from simdiff.errors import SimdiffError

FEATURE_DIM: int = 263

FEATURE_GROUPS: tuple[tuple[int, int], ...] = (
    (0, 1),  # root rotational velocity (rad/frame)
    (1, 3),  # root linear velocity x, z (m/frame)
    (3, 4),  # root height (m)
    (4, 67),  # ric: joints 1..21 relative to the root (m)
    (67, 193),  # local rotations, continuous 6D
    (193, 259),  # local joint velocities (m/frame)
    (259, 263),  # foot contacts
)
"""Half-open slices whose std entries HumanML3D replaces by the group's mean std."""

Array = TypeVar("Array", np.ndarray, torch.Tensor)


def _check_vector(values: np.ndarray, name: str) -> np.ndarray:
    values = np.asarray(values)
    if values.shape != (FEATURE_DIM,):
        raise SimdiffError(f"{name} must have shape ({FEATURE_DIM},), got {values.shape}")
    if not np.all(np.isfinite(values)):
        raise SimdiffError(f"{name} contains non-finite values")
    return values.astype(np.float32)


DEFAULT_STATS_DIR = Path(__file__).resolve().parents[1] / "assets" / "cmu_stats"
"""Mean/Std of the project's CMU corpus (train split), shipped with the package."""


class Normalizer:
    """Feature normaliser with ``mean`` and ``std``, each (263,) float32."""

    def __init__(self, mean: np.ndarray, std: np.ndarray) -> None:
        self.mean = _check_vector(mean, "mean")
        self.std = _check_vector(std, "std")
        if np.any(self.std <= 0):
            bad = int(np.argmin(self.std))
            raise SimdiffError(f"std must be positive, got std[{bad}]={self.std[bad]}")

    @classmethod
    def from_files(cls, mean_path: str | Path, std_path: str | Path) -> Normalizer:
        """Load a (263,) mean and std from two ``.npy`` files."""
        return cls(_load_vector(Path(mean_path)), _load_vector(Path(std_path)))

    @classmethod
    def from_dir(cls, path: str | Path) -> Normalizer:
        """Load ``Mean.npy`` and ``Std.npy`` from a HumanML3D-style directory."""
        path = Path(path)
        if not path.is_dir():
            raise SimdiffError(f"normalisation directory not found: {path}")
        return cls.from_files(path / "Mean.npy", path / "Std.npy")

    @classmethod
    def fit(cls, features: np.ndarray | Iterable[np.ndarray]) -> Normalizer:
        """Normaliser with the grouped HumanML3D statistics of ``features`` (see group_std)."""
        return cls(*group_std(features))

    def save(self, path: str | Path) -> None:
        """Write ``Mean.npy`` and ``Std.npy`` into directory ``path`` (created if needed)."""
        path = Path(path)
        path.mkdir(parents=True, exist_ok=True)
        from simdiff.fsio import save_npy

        save_npy(path / "Mean.npy", self.mean)
        save_npy(path / "Std.npy", self.std)

    def _stats_like(self, x: Array) -> tuple[Array, Array]:
        if x.shape[-1:] != (FEATURE_DIM,):
            raise SimdiffError(f"features must end in {FEATURE_DIM} channels, got shape {tuple(x.shape)}")
        if isinstance(x, torch.Tensor):
            dtype = x.dtype if x.is_floating_point() else torch.float32
            mean = torch.as_tensor(self.mean, device=x.device, dtype=dtype)
            return mean, torch.as_tensor(self.std, device=x.device, dtype=dtype)
        return self.mean, self.std

    def normalize(self, x: Array) -> Array:
        """(..., 263) raw features -> normalised; numpy in, numpy out; torch in, torch out."""
        if not isinstance(x, torch.Tensor):
            x = np.asarray(x, dtype=np.float32)
        mean, std = self._stats_like(x)
        return (x - mean) / std

    def denormalize(self, x: Array) -> Array:
        """(..., 263) normalised features -> raw (``x * std + mean``)."""
        if not isinstance(x, torch.Tensor):
            x = np.asarray(x, dtype=np.float32)
        mean, std = self._stats_like(x)
        return x * std + mean

    def __repr__(self) -> str:
        return f"Normalizer(mean[3]={self.mean[3]:.4f}, std[3]={self.std[3]:.4f})"


def default_normalizer() -> Normalizer:
    """The shipped CMU-corpus Mean/Std (see ``simdiff/assets/cmu_stats/README.md``)."""
    return Normalizer.from_dir(DEFAULT_STATS_DIR)


def _load_vector(path: Path) -> np.ndarray:
    if not path.is_file():
        raise SimdiffError(f"normalisation file not found: {path}")
    try:
        values = np.load(path, allow_pickle=False)
    except (OSError, ValueError) as exc:
        raise SimdiffError(f"cannot read {path}: {exc}") from None
    if values.ndim == 2 and 1 in values.shape:  # tolerate (1, 263) or (263, 1)
        values = values.reshape(-1)
    return _check_vector(values, str(path))


def _as_rows(features: np.ndarray | Iterable[np.ndarray]) -> list[np.ndarray]:
    """Flatten the input into a list of (N_i, 263) float64 arrays, skipping NaN clips."""
    if isinstance(features, (np.ndarray, torch.Tensor)):
        features = [np.asarray(features)]
    rows: list[np.ndarray] = []
    for i, item in enumerate(features):
        arr = np.asarray(item, dtype=np.float64)
        if arr.ndim < 1 or arr.shape[-1] != FEATURE_DIM:
            raise SimdiffError(f"features[{i}] must end in {FEATURE_DIM} channels, got shape {arr.shape}")
        arr = arr.reshape(-1, FEATURE_DIM)
        if np.isnan(arr).any():
            warnings.warn(f"group_std: skipping features[{i}], it contains NaN", stacklevel=3)
            continue
        rows.append(arr)
    if sum(len(r) for r in rows) == 0:
        raise SimdiffError("group_std needs at least one frame of finite features")
    return rows


def group_std(
    features: np.ndarray | Sequence[np.ndarray] | Iterable[np.ndarray],
) -> tuple[np.ndarray, np.ndarray]:
    """Mean and grouped Std the HumanML3D way (``cal_mean_variance``).

    Args:
        features: one array (..., 263) or a list of (T_i, 263) clips; every frame of every
            clip counts once. Clips containing NaN are skipped, as HumanML3D does.
    Returns:
        (mean, std), each (263,) float32. ``std`` is the per-channel population std with
        each group of FEATURE_GROUPS replaced by the mean of that group's entries.
    """
    rows = _as_rows(features)
    count = sum(len(r) for r in rows)
    mean = sum(r.sum(axis=0) for r in rows) / count
    var = sum(((r - mean) ** 2).sum(axis=0) for r in rows) / count
    std = np.sqrt(var)
    for start, stop in FEATURE_GROUPS:
        std[start:stop] = std[start:stop].mean()
    return mean.astype(np.float32), std.astype(np.float32)
