"""Put motions on the floor as HumanML3D puts its clips: the lowest joint over the clip at y = 0.

HumanML3D's processing shifts every clip vertically so that its lowest joint over all frames is at
height 0. A generated motion need not be: the shipped model's test samples stand with their own
floor (the 5th percentile of the lowest joint) 19 mm above y = 0 against the ground truth's 2 mm,
and under g = −1.6 with strong environment guidance its runs float a metre up. A
vertical shift of the whole clip changes no pose, no velocity and no contact; in the 263 features
it moves the root height (feature 3) and the heights of the "ric" joints (features 4..66, every
third from 5), which are heights above the floor.
"""

from __future__ import annotations

import torch

from simdiff.motion.features import SLICES
from simdiff.motion.contact_features import batch_features
from simdiff.motion.metrics import FLOOR_CLEARANCE

RIC_Y: slice = slice(SLICES["ric"].start + 1, SLICES["ric"].stop, 3)
"""The height channels of the 21 non-root joints in the features."""


def floor_offset(features: torch.Tensor, lengths: torch.Tensor | None = None) -> torch.Tensor:
    """(B,) metres: each clip's lowest joint height over its valid frames (0 for a clip on the floor).

    Args: features (B, T, 263) or (T, 263) un-normalised; lengths (B,) valid frames (None: all).
    """
    f, single, valid = batch_features(features, lengths, "floor_offset")
    out = _lowest(f, valid)
    return out[0] if single else out


def _lowest(f: torch.Tensor, valid: torch.Tensor) -> torch.Tensor:
    """(B,) lowest joint height over the valid frames, read straight from the height channels (the heading
    rotation of the "ric" channels is about Y, so heights need no forward kinematics)."""
    low = torch.cat([f[..., SLICES["root_y"]], f[..., RIC_Y]], dim=-1).amin(dim=-1)  # (B, T)
    return torch.where(valid, low, torch.full_like(low, float("inf"))).amin(dim=1)


def place_on_floor(features: torch.Tensor, lengths: torch.Tensor | None = None) -> torch.Tensor:
    """The clips shifted vertically so the lowest joint over each clip's valid frames is at y = 0.

    Args: features (B, T, 263) or (T, 263) un-normalised HumanML3D features (metres, Y-up, 20 fps);
        lengths (B,) valid frames (None: all T); frames past a length are returned unchanged.
    Returns: the same shape and dtype.
    """
    return _shift_down(features, lengths, "place_on_floor", only_above=None)


def drop_floating(features: torch.Tensor, lengths: torch.Tensor | None = None,
                  clearance: float = FLOOR_CLEARANCE) -> torch.Tensor:
    """Only the clips that never touch the floor, put on it: a clip whose lowest joint stays more than
    ``clearance`` m above y = 0 in every valid frame (:func:`simdiff.motion.metrics.never_touches`) is shifted
    down so its lowest joint over the clip is at y = 0; every other clip is returned unchanged, bit for bit.

    Args and returns as :func:`place_on_floor`.
    """
    return _shift_down(features, lengths, "drop_floating", only_above=clearance)


def _shift_down(features: torch.Tensor, lengths: torch.Tensor | None, name: str,
                only_above: float | None) -> torch.Tensor:
    """The clips lowered by their lowest joint height (all, or only those whose lowest joint is above ``only_above``)."""
    f, single, valid = batch_features(features, lengths, name)
    low = _lowest(f, valid)
    if only_above is not None:
        low = torch.where(low > only_above, low, torch.zeros_like(low))
    d = low[:, None, None] * valid[..., None]  # (B, T, 1)
    f[..., SLICES["root_y"]] -= d
    f[..., RIC_Y] -= d
    out = f.to(features.dtype)
    return out[0] if single else out
