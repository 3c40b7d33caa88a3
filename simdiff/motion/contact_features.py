"""What the foot passes (:mod:`.foot_lock`, :mod:`.foot_clearance`, :mod:`.floor`) share: a float64 working copy
of a feature batch with its valid-frame mask, the rotation into the root-facing frame, and the contact threshold.
Kept apart from the passes so that they import it and not one another."""

from __future__ import annotations

import torch

from simdiff.errors import SimdiffError

CONTACT_THRESHOLD: float = 0.5
"""A contact channel above this marks its joint as planted (the channels are 0/1 in the data)."""


def batch_features(features: torch.Tensor, lengths: torch.Tensor | None, what: str) -> tuple[torch.Tensor, bool, torch.Tensor]:
    """A float64 working copy (B, T, 263) of (B, T, 263) or (T, 263) features, whether the input was one clip, and
    the (B, T) bool mask of valid frames (``lengths`` (B,), None: all T); ``what`` names the caller in the error."""
    single = features.dim() == 2
    f = (features[None] if single else features).detach().to(torch.float64).clone()
    if f.shape[-1] != 263 or f.shape[-2] < 2:
        raise SimdiffError(f"{what} needs (B, T >= 2, 263) features, got {tuple(features.shape)}")
    b, t = f.shape[:2]
    lens = torch.full((b,), t, dtype=torch.long) if lengths is None else torch.as_tensor(lengths).long().cpu()
    return f, single, (torch.arange(t)[None] < lens[:, None]).to(f.device)


def yaw_rotate(half: torch.Tensor, x: torch.Tensor, z: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
    """World (x, z) into the root-facing frame of yaw half-angle ``half`` (inverse of features' un-rotation)."""
    c, s = torch.cos(2 * half), torch.sin(2 * half)
    return c * x + s * z, -s * x + c * z
