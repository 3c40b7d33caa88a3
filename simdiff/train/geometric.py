"""MDM's geometric training losses on joint positions, and length-cropped batches.

MDM (facts: ``lambda_rcxyz``, ``lambda_vel``, ``lambda_fc``) adds to the x₀ MSE, on the
joints recovered from the predicted and target features:

* position: masked MSE of joint positions (metres);
* velocity: masked MSE of joint velocities (m/s, frame pairs whose both frames are valid);
* foot contact: squared predicted velocity (m/s) of the ankle/toe joints (7, 10, 8, 11) on
  the frame pairs where the *target's* contact channels (259:263) say the foot is planted.

All weights default to 0 (MDM's HumanML3D setting), which leaves training unchanged.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import torch
from torch import Tensor

from simdiff.motion.features import features_to_joints
from simdiff.motion.skeleton import FPS

FOOT_JOINTS: tuple[int, ...] = (7, 10, 8, 11)
"""Left ankle, left toe, right ankle, right toe: the order of the contact channels 259..262."""
CONTACT_SLICE = slice(259, 263)


@dataclass
class GeometricLossConfig:
    """Weights of the geometric terms (0 = off, MDM's HumanML3D default)."""

    position: float = 0.0
    velocity: float = 0.0
    foot_contact: float = 0.0

    @property
    def active(self) -> bool:
        return self.position > 0 or self.velocity > 0 or self.foot_contact > 0


@dataclass
class CropConfig:
    """Length-cropped batches.

    Attributes:
        max_frames: crop each clip to a random window of at most this many frames (a multiple
            of 4; 0 = off) and cut the batch to that width.
        trim_padding: cut the batch to its longest clip (rounded up to 4 frames) instead of
            the dataset's padded 196 frames. Changes what MDM's unmasked attention sees.
    """

    max_frames: int = 0
    trim_padding: bool = False

    @property
    def active(self) -> bool:
        return self.max_frames > 0 or self.trim_padding


def crop_batch(batch: dict[str, Any], config: CropConfig, rng: np.random.Generator, pairs: int = 0) -> dict[str, Any]:
    """Apply ``config`` to a collated batch (motion (B, T, F), lengths, mask) in place; returns it.

    ``pairs`` = h > 0: items ``i`` and ``i + h`` (i < h) are twins and get the same window start, drawn over the
    frames they share (twins of unequal length start at their first frames: ``twin_frames="overlap"``).
    """
    if not config.active:
        return batch
    motion, lengths = batch["motion"], batch["lengths"].clone()
    width = motion.shape[1]
    if config.max_frames > 0:
        cap = max(4, config.max_frames // 4 * 4)
        motion = motion.clone()
        offsets: dict[int, int] = {}
        full = lengths.tolist()
        for i, n in enumerate(full):
            twin_of = i - pairs if pairs and i >= pairs else -1
            if twin_of >= 0 and twin_of in offsets:
                off = offsets[twin_of]  # the window its twin got (0 when the shared frames fit in one)
            else:
                twin = i + pairs if pairs and i < pairs else -1
                common = n if twin < 0 else min(n, full[twin])
                off = offsets[i] = int(rng.integers(common - cap + 1)) if common > cap else 0
            if n > cap or off:
                window = motion[i, off: off + min(cap, n - off)].clone()
                motion[i] = 0.0
                motion[i, : len(window)] = window
                lengths[i] = len(window)
        width = min(width, cap)
    if config.trim_padding:
        width = min(width, int(-(-int(lengths.max()) // 4) * 4))
    batch["motion"] = motion[:, :width].contiguous()
    batch["lengths"] = lengths
    batch["mask"] = torch.arange(width)[None, :] < lengths[:, None]
    return batch


def geometric_loss(pred: Tensor, target: Tensor, mask: Tensor, mean: Tensor, std: Tensor,
                   config: GeometricLossConfig) -> Tensor:
    """Weighted sum of the enabled terms.

    Args:
        pred, target: (B, T, 263) normalised features; mask: (B, T) valid frames.
        mean, std: (263,) the normaliser (to recover metres).
    """
    zero = pred.new_zeros(())
    if not config.active:
        return zero
    mean, std = mean.to(pred), std.to(pred)
    raw_pred, raw_target = pred * std + mean, target * std + mean
    jp, jt = features_to_joints(raw_pred), features_to_joints(raw_target)  # (B, T, 22, 3)
    m = mask.to(pred.dtype)
    total = zero
    if config.position > 0:
        err = ((jp - jt) ** 2).mean(dim=(-1, -2))
        total = total + config.position * (err * m).sum() / m.sum().clamp_min(1.0)
    pair = m[:, 1:] * m[:, :-1]
    vp = (jp[:, 1:] - jp[:, :-1]) * FPS
    if config.velocity > 0:
        vt = (jt[:, 1:] - jt[:, :-1]) * FPS
        err = ((vp - vt) ** 2).mean(dim=(-1, -2))
        total = total + config.velocity * (err * pair).sum() / pair.sum().clamp_min(1.0)
    if config.foot_contact > 0:
        contact = (raw_target[:, :-1, CONTACT_SLICE] > 0.5).to(pred.dtype) * pair[..., None]  # (B, T-1, 4)
        foot_v = (vp[:, :, list(FOOT_JOINTS)] ** 2).sum(-1)  # (B, T-1, 4)
        total = total + config.foot_contact * (foot_v * contact).sum() / contact.sum().clamp_min(1.0)
    return total
