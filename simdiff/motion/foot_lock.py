"""The foot cleanup (``foot_lock``): what a motion's feet need beyond what the network drew.

Two passes run on the sampled features (:func:`clean_feet`): swinging feet that drag along the floor are lifted
clear of it, the knee re-solved (:mod:`simdiff.motion.foot_clearance`), and a clip that never comes within 0.10 m
of the floor is lowered onto it (:func:`simdiff.motion.floor.drop_floating`). The third, holding planted feet in
place, runs on the written joints, after the rigid fit, by leg IK (:mod:`simdiff.motion.contact_hold`, through
:func:`simdiff.motion.rigid.joints_from_features`): the root keeps the network's path. (Moving the root to pin the
feet gave one-frame root jumps of up to 21.5 m/s in 13 of 456 default-setting motions.)
"""

from __future__ import annotations

import numpy as np
import torch

from simdiff.motion.floor import drop_floating
from simdiff.motion.foot_clearance import clear_swing_feet

CLEANUP_VERSION: int = 4
"""What ``foot_lock`` does: 1 a root-shifting lock, 2 that and the swing-foot clearance, 3 those and a floating
clip dropped onto the floor, 4 clearance and drop in the features, planted feet held by leg IK in the joints.
Cached measurements made with a foot lock carry it in their fingerprint."""


def clean_feet(features: torch.Tensor, lengths: torch.Tensor | None = None, strength: float = 1.0) -> torch.Tensor:
    """The generator's feature passes at ``strength`` in [0, 1]: swinging feet lifted clear of the floor
    (:func:`simdiff.motion.foot_clearance.clear_swing_feet`), then, whatever the strength > 0, a clip that never
    comes within 0.10 m of the floor lowered onto it (:func:`simdiff.motion.floor.drop_floating`; clips that touch
    it are not moved). ``features`` (B, T, 263) or (T, 263) un-normalised, ``lengths`` (B,) valid frames."""
    cleaned = clear_swing_feet(features, lengths, strength)
    return drop_floating(cleaned, lengths) if strength > 0 else cleaned


def clean_feet_numpy(features: np.ndarray, strength: float = 1.0) -> np.ndarray:
    """:func:`clean_feet` for one (T, 263) numpy clip (float32 out)."""
    return clean_feet(torch.as_tensor(np.asarray(features, dtype=np.float32)), strength=strength).numpy()
