"""Keyframe constraints for ``simdiff generate --keyframes FILE.npy``.

A keyframe file is a (T, 22, 3) joints array (metres, Y up, 20 fps) with NaN for "free": whole poses pin
in-betweens and continuations, a root's x/z alone makes a path. During denoising every x̂₀ prediction is pulled
onto the finite entries by a few gradient steps through the joint decoding (:class:`KeyframeGuide`, an
:data:`simdiff.diffusion.sampling.X0Hook`); the network then carries the motion on around them. The finished
sample gets more such steps (:meth:`KeyframeGuide.polish`).

Generated motions start at the origin facing +Z; keyframes whose frame 0 places the root elsewhere or faces
elsewhere are moved into that frame first (:func:`keyframe_frame`) and the motion is moved back after.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import torch
from torch import Tensor

from simdiff.errors import SimdiffError
from simdiff.motion.skeleton import (
    FACE_JOINTS,
    MAX_FRAMES,
    MIN_GENERATE_FRAMES,
    NUM_JOINTS,
)

GUIDE_STEPS: int = 20
"""Gradient steps on x̂₀ per denoising step."""
POLISH_STEPS: int = 200
"""Gradient steps on the finished sample."""
LEARNING_RATE: float = 0.2
"""Adam's step on the normalised features."""
CORRECTION_SIGMA: float = 3.0
"""Gaussian σ in frames of the corrections: a keyframe moves its neighbours too, so the motion gets there
without a jump."""
MAX_BONE_SPREAD: float = 0.02
"""m: the most one bone's length may differ between the whole poses given (they are one body)."""
MIN_BODY_JOINTS: int = 4
"""Joints given at a frame without the root from which the body's position there is taken."""
BLEND_FRAMES: int = 10
"""Frames either side of a keyframe over which :func:`meet_keyframes` fades its pose correction."""
MAX_COORDINATE: float = 1000.0
"""m: the largest keyframe coordinate (a motion stays within a kilometre of the origin)."""
MAX_KEYFRAME_SPEED: float = 20.0
"""m/s: two finite entries of one joint further apart than this over their frames cannot both be met."""


def load_keyframes(path: str | Path) -> np.ndarray:
    """Read and check a keyframe file: float64 (T, 22, 3), T in 10..196, NaN = free, at least one finite entry,
    no infinities, finite entries reachable from each other at :data:`MAX_KEYFRAME_SPEED`; one-line errors."""
    path = Path(path)
    try:
        keys = np.load(path, allow_pickle=False)
    except FileNotFoundError:
        raise SimdiffError(f"no keyframe file {str(path)!r}") from None
    except (OSError, ValueError) as exc:
        raise SimdiffError(f"{path}: not a .npy array ({exc})") from None
    return check_keyframes(keys, str(path))


def check_keyframes(keys: np.ndarray, name: str = "the keyframes") -> np.ndarray:
    """:func:`load_keyframes`' checks on an array."""
    keys = np.asarray(keys)
    if keys.dtype.kind not in "fiu":
        raise SimdiffError(f"{name} must be a float array, got dtype {keys.dtype}")
    keys = keys.astype(np.float64)
    if keys.ndim != 3 or keys.shape[1:] != (NUM_JOINTS, 3):
        raise SimdiffError(f"{name} must be (T, 22, 3) joints with NaN for free entries, got shape {keys.shape}")
    if not MIN_GENERATE_FRAMES <= keys.shape[0] <= MAX_FRAMES:
        raise SimdiffError(f"{name} has {keys.shape[0]} frames; a motion is {MIN_GENERATE_FRAMES}..{MAX_FRAMES} "
                           "frames (0.5..9.8 s at 20 fps)")
    if np.isinf(keys).any():
        frame = int(np.argwhere(np.isinf(keys))[0][0])
        raise SimdiffError(f"{name} has an infinite value at frame {frame}; use NaN for free entries")
    finite = np.isfinite(keys)
    if not finite.any():
        raise SimdiffError(f"{name} are all NaN: nothing is constrained")
    partly = (finite.sum(-1) % 3) > 0  # (T, 22)
    partly[:, 0] &= ~(finite[:, 0, 0] & finite[:, 0, 2] & ~finite[:, 0, 1])  # the root's x/z alone is a path
    if partly.any():
        frame, joint = (int(v) for v in np.argwhere(partly)[0])
        raise SimdiffError(f"{name}: joint {joint} at frame {frame} is partly NaN; give x, y and z (or, for the "
                           "root, x and z alone)")
    if np.abs(keys[finite]).max() > MAX_COORDINATE:
        frame = int(np.argwhere(np.abs(np.nan_to_num(keys)) > MAX_COORDINATE)[0][0])
        raise SimdiffError(f"{name} has a coordinate beyond {MAX_COORDINATE:g} m at frame {frame}; joints are metres")
    _check_reachable(keys, name)
    _check_skeleton(keys, name)
    return keys


def _check_skeleton(keys: np.ndarray, name: str) -> None:
    """The whole poses given must be one body: bones 2 cm..1 m, each the same length in every pose (±2 cm)."""
    from simdiff.motion.rigid import bone_lengths

    posed = np.flatnonzero(np.isfinite(keys).all(axis=(1, 2)))
    if not len(posed):
        return
    lengths = bone_lengths(keys[posed])  # (K, 21)
    bad = np.argwhere((lengths < 0.02) | (lengths > 1.0))
    if len(bad):
        k, b = (int(v) for v in bad[0])
        raise SimdiffError(f"{name}: the pose at frame {posed[k]} has a bone (to joint {b + 1}) {lengths[k, b]:.3f} m "
                           "long; not a body in metres")
    spread = lengths.max(0) - lengths.min(0)
    if spread.max() > MAX_BONE_SPREAD:
        b = int(spread.argmax())
        raise SimdiffError(f"{name}: the bone to joint {b + 1} is {lengths[:, b].min():.3f}..{lengths[:, b].max():.3f} m "
                           "long across the given poses; they must be one skeleton")


def _check_reachable(keys: np.ndarray, name: str) -> None:
    """Two finite entries of one joint that would need more than :data:`MAX_KEYFRAME_SPEED` between them."""
    from simdiff.motion.skeleton import FPS

    for joint in range(NUM_JOINTS):
        for axes in ((0, 2),) if joint == 0 else ((0, 1, 2),):
            frames = np.flatnonzero(np.isfinite(keys[:, joint, list(axes)]).all(-1))
            if len(frames) < 2:
                continue
            pos = keys[frames][:, joint][:, list(axes)]
            speed = np.linalg.norm(np.diff(pos, axis=0), axis=-1) / (np.diff(frames) / FPS)
            if speed.max() > MAX_KEYFRAME_SPEED:
                i = int(speed.argmax())
                raise SimdiffError(f"{name}: joint {joint} moves {speed[i]:.0f} m/s between frames {frames[i]} and "
                                   f"{frames[i + 1]}; no motion reaches that (limit {MAX_KEYFRAME_SPEED:g} m/s)")


@dataclass(frozen=True)
class KeyframeFrame:
    """The yaw (radians, about +Y) and x/z offset (metres) that take a generated motion (frame 0 at the origin
    facing +Z) to the keyframes' frame."""

    yaw: float = 0.0
    offset: tuple[float, float] = (0.0, 0.0)

    def _turn(self, joints: np.ndarray, angle: float) -> np.ndarray:
        """(..., 3) positions turned about +Y by ``angle`` (x and z mixed explicitly so that a free y stays free)."""
        c, s = np.cos(angle), np.sin(angle)
        out = np.array(joints, dtype=np.float64, copy=True)
        out[..., 0] = c * joints[..., 0] + s * joints[..., 2]
        out[..., 2] = -s * joints[..., 0] + c * joints[..., 2]
        return out

    def to_keyframes(self, joints: np.ndarray) -> np.ndarray:
        """(..., 3) positions of a generated motion → the keyframes' frame."""
        out = self._turn(joints, self.yaw)
        out[..., 0] += self.offset[0]
        out[..., 2] += self.offset[1]
        return out

    def to_generated(self, joints: np.ndarray) -> np.ndarray:
        """(..., 3) positions in the keyframes' frame → a generated motion's frame (NaN stays NaN)."""
        out = np.array(joints, dtype=np.float64, copy=True)
        out[..., 0] -= self.offset[0]
        out[..., 2] -= self.offset[1]
        return self._turn(out, -self.yaw)


def keyframe_frame(keys: np.ndarray) -> KeyframeFrame:
    """Where frame 0 of the keyframes puts the root (its x/z when given, else the middle of at least
    :data:`MIN_BODY_JOINTS` joints given) and which way it faces (when the hips and shoulders are given); the origin
    and +Z otherwise."""
    given = np.isfinite(keys[0]).all(-1)
    if np.isfinite(keys[0, 0, [0, 2]]).all():
        offset = (float(keys[0, 0, 0]), float(keys[0, 0, 2]))
    elif given.sum() >= MIN_BODY_JOINTS:  # the root sits near the middle of the body given
        offset = (float(keys[0, given, 0].mean()), float(keys[0, given, 2].mean()))
    else:
        offset = (0.0, 0.0)
    a, b, c, d = FACE_JOINTS
    if not np.isfinite(keys[0, [a, b, c, d]]).all():
        return KeyframeFrame(0.0, offset)
    across = (keys[0, a] - keys[0, b]) + (keys[0, c] - keys[0, d])
    forward = np.cross([0.0, 1.0, 0.0], across)
    return KeyframeFrame(float(np.arctan2(forward[0], forward[2])), offset)


class KeyframeGuide:
    """Pull x̂₀ onto keyframes: ``guide(x0 (B, T, F) normalised, t, x_t) -> x0'``.

    Args:
        targets: (T, 22, 3) positions in the generated motion's frame, NaN = free.
        mean, std: (F,) feature statistics of the model.
    """

    def __init__(self, targets: np.ndarray, mean: Tensor, std: Tensor) -> None:
        t = torch.as_tensor(np.asarray(targets), dtype=torch.float32, device=mean.device)
        self.mask = torch.isfinite(t)
        self.targets = torch.nan_to_num(t)
        self.mean, self.std = mean, std
        r = int(3 * CORRECTION_SIGMA)
        k = torch.exp(-0.5 * (torch.arange(-r, r + 1, dtype=torch.float32, device=mean.device) / CORRECTION_SIGMA) ** 2)
        self.kernel = (k / k.sum()).reshape(1, 1, -1)

    def error(self, x0: Tensor) -> Tensor:
        """(B,) mean squared distance (m²) of the decoded joints from the finite entries."""
        from simdiff.motion.features import features_to_joints

        joints = features_to_joints(x0 * self.std + self.mean)
        n = self.mask.shape[0]
        diff = (joints[:, :n] - self.targets) * self.mask
        return diff.pow(2).sum(dim=(1, 2, 3)) / self.mask.sum()

    def pull(self, x0: Tensor, steps: int) -> Tensor:
        """``x0`` plus a correction, smooth in time (:data:`CORRECTION_SIGMA`), after ``steps`` Adam steps on
        :meth:`error`."""
        with torch.enable_grad():
            z = torch.zeros_like(x0, requires_grad=True)
            opt = torch.optim.Adam([z], lr=LEARNING_RATE)
            for _ in range(steps):
                opt.zero_grad()
                self.error(x0 + self._smooth(z)).sum().backward()
                opt.step()
        return (x0 + self._smooth(z)).detach()

    def _smooth(self, z: Tensor) -> Tensor:
        """(B, T, F) low-passed along T by the Gaussian kernel, the end values repeated beyond the ends."""
        b, t, f = z.shape
        k = self.kernel
        pad = min(k.shape[-1] // 2, t - 1)
        y = z.transpose(1, 2).reshape(b * f, 1, t)
        y = torch.nn.functional.pad(y, (pad, pad), mode="replicate")
        y = torch.nn.functional.conv1d(y, k[..., k.shape[-1] // 2 - pad: k.shape[-1] // 2 + pad + 1])
        return y.reshape(b, f, t).transpose(1, 2)

    def __call__(self, x0: Tensor, t: int, x_t: Tensor) -> Tensor:
        return self.pull(x0, GUIDE_STEPS)

    def polish(self, x0: Tensor) -> Tensor:
        """The finished sample's x₀ after :data:`POLISH_STEPS` more steps."""
        return self.pull(x0, POLISH_STEPS)


def _interpolate(frames: np.ndarray, values: np.ndarray, length: int) -> np.ndarray:
    """Piecewise-linear (length, D) through ``values`` (K, D) at ``frames`` (K,), constant beyond the ends."""
    return np.stack([np.interp(np.arange(length), frames, values[:, d]) for d in range(values.shape[1])], axis=1)


def _faded(frames: np.ndarray, residuals: np.ndarray, length: int) -> np.ndarray:
    """(length, ...) correction: each residual (K, ...) exactly at its frame (K,) (sorted), linear between
    neighbouring frames, scaled by an envelope that falls to 0 over :data:`BLEND_FRAMES` away from the nearest."""
    t = np.arange(length)
    gap = np.min(np.abs(t[:, None] - frames[None]), axis=1)
    envelope = np.clip(1.0 - gap / (BLEND_FRAMES + 1), 0.0, 1.0)
    flat = residuals.reshape(len(frames), -1)
    lin = _interpolate(frames, flat, length).reshape((length,) + residuals.shape[1:])
    return lin * envelope.reshape((length,) + (1,) * (residuals.ndim - 1))


def meet_keyframes(joints: np.ndarray, keys: np.ndarray, skeleton: np.ndarray | None = None) -> np.ndarray:
    """Written joints (T, 22, 3) brought onto the keyframes (T, 22, 3, NaN = free), both in one frame: the whole
    body shifted by the root's residuals (or, where the root is free, the mean residual of at least
    :data:`MIN_BODY_JOINTS` given joints; interpolated between the frames that give them), then each given pose's
    residual faded in and out over :data:`BLEND_FRAMES` (joints given alone likewise), then rotations fitted again on
    ``skeleton`` ((22, 3) rest offsets; default: that of the given poses, the motion's own when no whole pose is
    given) and turned by inverse kinematics onto every given coordinate within reach (:func:`simdiff.motion.reach.reach`;
    the fit alone left a wrist given without its pose 15 cm off). float32 (T, 22, 3)."""
    from simdiff.motion.reach import reach
    from simdiff.motion.rigid import fit, rest_offsets

    out = np.asarray(joints, dtype=np.float64).copy()
    n = out.shape[0]
    shift = keys[:, 0] - out[:, 0]  # (T, 3): the root's residual where given, else the body's mean residual
    body = np.isfinite(keys).all(-1)  # (T, 22)
    bodily = ~np.isfinite(shift).all(-1) & (body.sum(-1) >= MIN_BODY_JOINTS)
    for f in np.flatnonzero(bodily):
        shift[f] = (keys[f, body[f]] - out[f, body[f]]).mean(0)
    for axis in range(3):
        given = np.flatnonzero(np.isfinite(shift[:, axis]))
        if len(given):
            out[..., axis] += _interpolate(given, shift[given, axis][:, None], n)
    posed = np.flatnonzero(np.isfinite(keys[:, 1:]).all(axis=(1, 2)))
    if len(posed):
        out[:, 1:] += _faded(posed, keys[posed, 1:] - out[posed, 1:], n)
    alone = np.isfinite(keys[:, 1:]).all(-1) & ~np.isfinite(keys[:, 1:]).all(axis=(1, 2))[:, None]  # (T, 21)
    for j in np.flatnonzero(alone.any(0)):  # joints given without their whole pose: faded the same way, per joint
        frames = np.flatnonzero(alone[:, j])
        out[:, j + 1] += _faded(frames, keys[frames, j + 1] - out[frames, j + 1], n)
    if skeleton is None and len(posed):  # the given poses' skeleton; a root given by x/z alone sits where it is put
        given = keys[posed].copy()
        given[:, 0] = np.where(np.isfinite(given[:, 0]), given[:, 0], out[posed, 0])
        skeleton = rest_offsets(given)
    if skeleton is None:
        skeleton = rest_offsets(out)
    return reach(fit(out, skeleton), keys).joints


def keyframe_error(joints: np.ndarray, keys: np.ndarray) -> float:
    """The largest distance (m) of ``joints`` (T, 22, 3) from the finite entries of ``keys`` (T, 22, 3)."""
    given = np.isfinite(keys)
    return float(np.linalg.norm(np.where(given, joints - np.nan_to_num(keys), 0.0), axis=-1).max())


def sample_keyframed(generator, keys: np.ndarray, config, *, text_embeddings: Tensor,
                     env: tuple[float, float, float] | None = None, seed: int = 0, progress=None,
                     skeleton: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """One motion of ``keys``' T frames meeting ``keys`` (T, 22, 3, NaN = free, checked): the guided sample, its
    polish, the written joints (:func:`simdiff.motion.rigid.joints_from_features` at ``config.foot_lock``) moved
    into the keyframes' frame and :func:`meet_keyframes`. ``generator``: a
    :class:`~simdiff.inference.generator.MotionGenerator`; ``text_embeddings`` (1, text_dim); ``skeleton`` as
    :func:`meet_keyframes`'. Returns the
    features (T, 263) (the sample's own frame) and the joints (T, 22, 3), float32."""
    from simdiff.motion.rigid import joints_from_features

    frame = keyframe_frame(keys)
    guide = KeyframeGuide(frame.to_generated(keys), generator.mean, generator.std)
    out = generator.generate([""], int(keys.shape[0]), config, env=env, seed=seed, text_embeddings=text_embeddings,
                             progress=progress, x0_hook=guide)
    clip = out.clips()[0].detach()
    # the cleaned sample pulled onto the keyframes once more
    normalised = guide.polish(((clip - generator.mean) / generator.std)[None])[0]
    features = (normalised * generator.std + generator.mean).cpu().numpy().astype(np.float32)
    joints = meet_keyframes(frame.to_keyframes(joints_from_features(features, config.foot_lock)), keys, skeleton)
    return features, joints
