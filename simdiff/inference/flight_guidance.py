"""Flight guidance: every flight of the x₀ prediction bent onto a parabola of the requested gravity.

A body in free flight moves its centre of mass on a parabola whose curvature is g. At each denoising step at or
below ``edit_t`` the x̂₀ prediction is decoded to joints, its readable flights are found as
:func:`simdiff.motion.gravity_readout.flight_fits` finds them (every foot more than 5 cm up, at least 5 frames), and
the body's height over each flight is moved onto the best parabola of curvature g (``y − g t²/2`` fitted by a
line), so the flight keeps its timing and its arc gets the curvature g. The move fades out over
:data:`FADE_FRAMES` frames either side, so the stance next to a flight follows without a step, and it never takes
a foot below the floor. The network then denoises from the corrected prediction, so the rest of the body carries
on around the new arc. It runs at every denoising step, the last one included (so the sample's flights are on
their parabolas before the foot cleanup), and leaves a motion without a readable flight exactly as sampled. Whether
a motion flies, and for how long, is the network's answer to the text and φ; the guidance makes the arcs physical.
Features (B, T, 263) normalised on the way in and out; heights in metres, g in m/s² (negative: down).
"""

from __future__ import annotations

from typing import Iterable, Sequence

import numpy as np
import torch
from torch import Tensor

from simdiff.diffusion.config import SamplingConfig
from simdiff.diffusion.sampling import X0Hook
from simdiff.motion.features import SLICES, features_to_joints
from simdiff.motion.flight import LIFT_EDGE, heights_over_ground
from simdiff.motion.gravity_readout import centre_of_mass, flight_fits
from simdiff.motion.skeleton import FPS, NUM_JOINTS

FADE_FRAMES: int = 4
"""Frames either side of a flight over which its height correction fades to zero."""

HEIGHT_CHANNELS: list[int] = [SLICES["root_y"].start] + [SLICES["ric"].start + 3 * k + 1 for k in range(NUM_JOINTS - 1)]
"""The feature channels holding joint heights: the root's and the 21 "ric" joints' y."""


def flight_correction(joints: np.ndarray, gravity: float) -> np.ndarray:
    """(T,) m: the height change that puts every readable flight of ``joints`` (T, 22, 3) on a parabola of
    curvature ``gravity`` (m/s²), faded out over :data:`FADE_FRAMES` either side; a faded frame is never lifted
    off the floor (its lowest foot stays within :data:`~simdiff.motion.flight.LIFT_EDGE`) and no frame takes a
    foot below it; zero without a readable flight."""
    frames = joints.shape[0]
    height = centre_of_mass(joints)[:, 1]
    fitted = np.zeros(frames)
    inside = np.zeros(frames, dtype=bool)
    faded, ramps = np.zeros(frames), np.zeros(frames)
    for fit in flight_fits(joints):
        s, e = fit.start, fit.end
        t = np.arange(e - s) / FPS
        free = height[s:e] - gravity * t**2 / 2.0
        line = np.stack([t, np.ones_like(t)], axis=1)
        coef, *_ = np.linalg.lstsq(line, free, rcond=None)
        fitted[s:e] = line @ coef - free
        inside[s:e] = True
        for k in range(1, FADE_FRAMES + 1):
            ramp = 1.0 - k / (FADE_FRAMES + 1)
            for frame, edge in ((s - k, fitted[s]), (e - 1 + k, fitted[e - 1])):
                if 0 <= frame < frames:
                    faded[frame] += ramp * edge
                    ramps[frame] += ramp
    lowest = heights_over_ground(joints).min(axis=1)
    # fades of neighbouring flights blend by their ramps; a flight's own frames take its own parabola
    fade = np.where(inside, 0.0, faded / np.maximum(ramps, 1.0))
    # a lifted stance frame would lengthen the flight the network chose (and lift planted feet)
    fade = np.minimum(fade, np.maximum(LIFT_EDGE - lowest, 0.0))
    # no foot pushed below the floor: that would move the floor the flights are found from (and is no flight)
    return np.maximum(np.where(inside, fitted, fade), -np.maximum(lowest, 0.0))


class FlightGuide:
    """An :data:`simdiff.diffusion.sampling.X0Hook` that bends each row's flights onto a parabola of its gravity.

    Args:
        gravity: (B,) g_z per row in m/s².
        mean, std: (F,) the model's feature statistics.
        passes: corrections per call, each on the decoding of the last; flights found on the moved motion can
            differ from the first decoding's, so one pass is not enough.
        max_t: the highest timestep guided (the sampling's ``edit_t``: above it a row follows its Earth sample).
        lengths: (B,) frames of each row's motion (None: all frames); the padding after them is left alone.
    """

    def __init__(self, gravity: Sequence[float] | np.ndarray, mean: Tensor, std: Tensor, passes: int,
                 max_t: int = 999, lengths: Sequence[int] | None = None) -> None:
        self.gravity = np.asarray(gravity, dtype=np.float64).reshape(-1)
        self.mean, self.std = mean, std
        self.passes = int(passes)
        self.max_t = int(max_t)
        self.lengths = None if lengths is None else [int(n) for n in lengths]

    def __call__(self, x0: Tensor, t: int, x_t: Tensor) -> Tensor:
        """x̂₀ (B, T, F) normalised → x̂₀ with its flights on parabolas of the rows' gravity."""
        if t > self.max_t or self.passes <= 0:
            return x0
        features = x0 * self.std + self.mean
        frames = features.shape[1]
        lengths = self.lengths or [frames] * features.shape[0]
        for _ in range(self.passes):
            joints = features_to_joints(features.detach().double()).cpu().numpy()
            moves = np.zeros((features.shape[0], frames))
            for row, (j, g, n) in enumerate(zip(joints, self.gravity, lengths)):
                moves[row, :n] = flight_correction(j[:n], g)
            if not moves.any():
                break
            features = features.clone()
            # heights only: also moving the vertical velocity channels lowered Moon jumps (val: apex 0.72 m against
            # 3.3 m, 8/12 against 10/12 within 20 % of −1.6)
            features[..., HEIGHT_CHANNELS] += torch.as_tensor(moves, dtype=features.dtype,
                                                              device=features.device)[..., None]
        return (features - self.mean) / self.std


def with_flight_guidance(hook: X0Hook | None, hook_timesteps: Iterable[int] | None, config: SamplingConfig,
                         gravity: Sequence[float], mean: Tensor, std: Tensor, lengths: Sequence[int]) -> X0Hook:
    """One hook for every timestep: ``hook`` at ``hook_timesteps`` (all when None), then the flight guidance of
    ``config.flight_passes`` passes at and below ``config.edit_t`` for rows of ``gravity`` (B,) m/s² and
    ``lengths`` (B,) frames."""
    guide = FlightGuide(gravity, mean, std, config.flight_passes, config.edit_t, lengths)
    if hook is None:
        return guide
    hooked = None if hook_timesteps is None else {int(t) for t in hook_timesteps}

    def guided(x0: Tensor, t: int, x_t: Tensor) -> Tensor:
        if hooked is None or int(t) in hooked:
            x0 = hook(x0, t, x_t)
        return guide(x0, t, x_t)

    return guided
