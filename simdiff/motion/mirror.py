"""Left/right mirroring of motions and captions (HumanML3D's ``M<id>`` augmentation).

Mirroring negates x (the character's left at frame 0) and swaps the left and right joint
chains; the caption swaps "left" and "right".
"""

from __future__ import annotations

import re
from typing import TypeVar

import numpy as np
import torch

from simdiff.errors import SimdiffError
from simdiff.motion.skeleton import NUM_JOINTS, mirror_permutation

Array = TypeVar("Array", np.ndarray, torch.Tensor)

_PERM = mirror_permutation()


def mirror_joints(joints: Array) -> Array:
    """Mirror joint positions across the YZ plane.

    Args:
        joints: (..., 22, 3) positions in metres (numpy or torch), e.g. (T, 22, 3).
    Returns:
        Same shape and type: x negated, left and right chains swapped.
    """
    if tuple(joints.shape[-2:]) != (NUM_JOINTS, 3):
        raise SimdiffError(f"joints must have shape (..., {NUM_JOINTS}, 3), got {tuple(joints.shape)}")
    if isinstance(joints, torch.Tensor):
        out = joints[..., torch.as_tensor(_PERM, device=joints.device), :].clone()
    else:
        out = np.array(np.asarray(joints)[..., _PERM, :], copy=True)
    out[..., 0] = -out[..., 0]
    return out


_SIDE_WORD = re.compile(r"\b(left|right|clockwise|counterclockwise|anticlockwise|counter-clockwise|anti-clockwise)(wards?)?\b", re.IGNORECASE)
_SWAP = {
    "left": "right",
    "right": "left",
    "clockwise": "counterclockwise",
    "counterclockwise": "clockwise",
    "anticlockwise": "clockwise",
    "counter-clockwise": "clockwise",
    "anti-clockwise": "clockwise",
}


def _match_case(template: str, word: str) -> str:
    if template.isupper() and len(template) > 1:
        return word.upper()
    if template[:1].isupper():
        return word[:1].upper() + word[1:]
    return word


def _swap_side(match: re.Match[str]) -> str:
    side, suffix = match.group(1), match.group(2) or ""
    return _match_case(side, _SWAP[side.lower()]) + suffix


def mirror_caption(text: str) -> str:
    """Swap the whole words left<->right (also -ward, -wards) and clockwise<->counterclockwise,
    keeping each word's case.

    "Turns LEFT, then steps rightwards" -> "Turns RIGHT, then steps leftwards"; words such as
    "leftover" or "bright" are untouched. Works on HumanML3D token strings ("left/ADJ") too.
    """
    if not isinstance(text, str):
        raise SimdiffError(f"caption must be a string, got {type(text).__name__}")
    return _SIDE_WORD.sub(_swap_side, text)


_CONTACT_SWAP = np.array([261, 262, 259, 260])
_ROT6D_SIGN = np.array([1.0, -1.0, -1.0, -1.0, 1.0, 1.0], dtype=np.float32)
_FLIP_X = np.array([-1.0, 1.0, 1.0], dtype=np.float32)


def mirror_features(features: np.ndarray, **process_kwargs: object) -> np.ndarray:
    """HumanML3D features of the mirrored motion, through the joint pipeline.

    Recovers joints from ``features`` (root and ric channels), rebuilds the frame after the
    last row, mirrors, and recomputes the features with
    ``simdiff.motion.features.joints_to_features`` (HumanML3D's processing: by default the
    mirrored body, whose left/right bone lengths are swapped, is retargeted to the canonical
    skeleton, as HumanML3D's ``M<id>`` clips are).

    Args:
        features: (T, 263) raw (un-normalised) features, T >= 1.
        **process_kwargs: passed to ``joints_to_features`` (e.g. ``uniform_skeleton=False``,
            which makes the result equal :func:`mirror_feature_channels` to float precision).
    Returns:
        (T, 263) float32 features.
    """
    from simdiff.motion import features as feats  # lazy: the IK pipeline is heavy

    arr = np.asarray(features, dtype=np.float32)
    if arr.ndim != 2 or arr.shape[1] != 263:
        raise SimdiffError(f"features must have shape (T, 263), got {arr.shape}")
    if arr.shape[0] < 1:
        raise SimdiffError("features need at least 1 frame, got 0")
    joints = feats.extend_last_frame(feats.features_to_joints(arr), arr)
    return np.asarray(feats.joints_to_features(mirror_joints(joints), **process_kwargs), dtype=np.float32)


def mirror_feature_channels(features: Array) -> Array:
    """Mirror HumanML3D features channel by channel, without recomputing them.

    Exact for the representation (it is its own inverse): root yaw velocity negated, x of the
    root velocity, ric and joint velocities negated, joints and foot contacts swapped
    left/right, 6D rotations conjugated by the reflection (``M R M``, M = diag(-1, 1, 1)). Equals
    ``mirror_features(f, uniform_skeleton=False)``; no retargeting of the swapped bones.

    Args:
        features: (..., 263) raw (un-normalised) features, numpy or torch, e.g. (B, T, 263).
    Returns:
        Same shape and type.
    """
    if features.shape[-1:] != (263,):
        raise SimdiffError(f"features must end in 263 channels, got shape {tuple(features.shape)}")
    lead = tuple(features.shape[:-1])
    joints21 = _PERM[1:] - 1  # joints 1..21 are stored at rows 0..20
    if isinstance(features, torch.Tensor):
        f = features
        dev, dt = f.device, f.dtype

        def take(x: torch.Tensor, idx: np.ndarray, dim: int) -> torch.Tensor:
            return x.index_select(dim, torch.as_tensor(idx, device=dev))

        sign3 = torch.as_tensor(_FLIP_X, device=dev, dtype=dt)
        sign6 = torch.as_tensor(_ROT6D_SIGN, device=dev, dtype=dt)
        cat = torch.cat
    else:
        f = np.asarray(features)

        def take(x: np.ndarray, idx: np.ndarray, dim: int) -> np.ndarray:
            return np.take(x, idx, axis=dim)

        sign3, sign6 = _FLIP_X.astype(f.dtype), _ROT6D_SIGN.astype(f.dtype)
        cat = np.concatenate
    ric = take(f[..., 4:67].reshape(lead + (21, 3)), joints21, f.ndim - 1) * sign3
    rot = take(f[..., 67:193].reshape(lead + (21, 6)), joints21, f.ndim - 1) * sign6
    vel = take(f[..., 193:259].reshape(lead + (22, 3)), _PERM, f.ndim - 1) * sign3
    parts = [
        -f[..., 0:2],  # yaw velocity and x velocity
        f[..., 2:4],  # z velocity and root height
        ric.reshape(lead + (63,)),
        rot.reshape(lead + (126,)),
        vel.reshape(lead + (66,)),
        take(f, _CONTACT_SWAP, f.ndim - 1),
    ]
    return cat(parts, -1)
