"""Ballistic flight: a body with no foot on the ground falls with the gravity it is under.

A generated flight (every foot joint off the floor: :func:`simdiff.motion.flight.flights`) may hang, float or
drop at a rate no gravity gives. Between the last frame on the ground before a flight (take-off, frame ``a``)
and the first frame on it after (landing, frame ``b``) nothing but gravity acts on the body, so its height
follows a parabola of curvature g through the take-off and landing heights:

    p(τ) = y_a + (y_b − y_a)·τ/D + ½·|g|·τ·(D − τ),   τ = (k − a)/fps,  D = (b − a)/fps,

rising |g|·D²/8 above the chord at mid-flight (0.20 m for a 0.4 s jump on Earth, 0.80 m for a 2 s flight under
g = −1.6). The whole body is moved vertically, frame by frame, by ``strength``·(p − y) with y the pelvis height
(the pelvis stands for the centre of mass; the poses, the horizontal path, the flight's timing and the contact
channels stay as generated). A flight still under way at the clip's last frame has no landing: it follows the
parabola from its take-off height whose take-off speed v0 fits its heights best (least squares over its frames), and
at least the speed that keeps it above the take-off height until that frame (½·|g|·D for D s in the air), since it
has not landed (a 5-s hover under g = −1.6 becomes a 5-m jump: what that flight time means under that gravity).
The body is never moved down through the floor: where the parabola lies lower than the lowest foot's clearance allows
(a flight too high for its duration under that g, e.g. a 0.75-m rise in 1 s under g = −1.6), it stops with that foot
on its ground level (the per-foot level of :mod:`simdiff.motion.flight`), i.e. the motion touches down there.
In the 263 features the shift moves the root height (feature 3), the "ric" heights of the other joints and the
vertical joint velocities.

Input: (B, T, 263) or (T, 263) un-normalised HumanML3D features, metres, Y-up, 20 fps; gravity as g_z m/s²
(negative, −9.81 on Earth), one per clip or one for all.
"""

from __future__ import annotations

from typing import Sequence

import numpy as np
import torch

from simdiff.errors import SimdiffError
from simdiff.motion.features import SLICES, features_to_joints
from simdiff.motion.flight import flights, heights_over_ground
from simdiff.motion.floor import RIC_Y
from simdiff.motion.foot_lock import batch_features
from simdiff.motion.skeleton import FPS

VEL_Y: slice = slice(SLICES["vel"].start + 1, SLICES["vel"].stop, 3)
"""The vertical velocity channels of the 22 joints in the features."""


def parabola_shift(height: np.ndarray, spans: Sequence[tuple[int, int]], g: float, fps: float = FPS,
                   clearance: np.ndarray | None = None) -> np.ndarray:
    """(T,) metres to add to ``height`` (T,) so each flight ``[s, e)`` of ``spans`` (take-off frame s − 1 ≥ 0) follows
    the parabola of gravity ``g`` m/s² (sign ignored) between take-off and landing (frame e), or from take-off with
    its best-fitting take-off speed, at least ½·|g|·D, when e = T (no landing in the clip, D s in the air).
    ``clearance`` (T,) m, when given: how far each frame may move down (its lowest foot's height over its ground);
    no frame is moved down by more."""
    h = np.asarray(height, dtype=np.float64)
    d = np.zeros_like(h)
    for s, e in spans:
        a, b = s - 1, e
        if a < 0:
            continue
        if b >= h.shape[0]:  # still in the air at the end: the take-off speed that fits the flight best
            tau = (np.arange(a, h.shape[0]) - a) / fps
            fall = h[a:] - h[a] + 0.5 * abs(g) * tau ** 2  # = v0·τ for a ballistic flight
            v0 = max(float(tau @ fall / (tau @ tau)), 0.5 * abs(g) * tau[-1])  # not down before the last frame
            d[a:] = h[a] + v0 * tau - 0.5 * abs(g) * tau ** 2 - h[a:]
            continue
        tau = (np.arange(a, b + 1) - a) / fps
        dur = (b - a) / fps
        p = h[a] + (h[b] - h[a]) * tau / dur + 0.5 * abs(g) * tau * (dur - tau)
        d[a:b + 1] = p - h[a:b + 1]
    if clearance is not None:
        d = np.maximum(d, -np.maximum(np.asarray(clearance, dtype=np.float64), 0.0))
    return d


def foot_clearance(joints: np.ndarray) -> np.ndarray:
    """(T,) m: the lowest foot joint's height over its own ground level
    (:func:`simdiff.motion.flight.heights_over_ground`) in each frame of ``joints`` (T, 22, 3)."""
    return heights_over_ground(joints).min(axis=1)


def ballistic_flights(features: torch.Tensor, gravity: float | Sequence[float] | torch.Tensor,
                      lengths: torch.Tensor | None = None, strength: float = 1.0, fps: float = FPS) -> torch.Tensor:
    """Features whose flights rise and fall as the given gravity makes them (see the module docstring).

    Args:
        features: (B, T, 263) or (T, 263) un-normalised features.
        gravity: g_z in m/s² (e.g. −9.81; the sign is ignored), a number or B finite numbers.
        lengths: (B,) valid frames (None: all T); frames past a length are returned unchanged.
        strength: share of the correction applied, in [0, 1] (0: unchanged, 1: exactly ballistic).
        fps: frames per second.
    Returns:
        Features of the same shape, dtype and device.
    """
    if not 0.0 <= strength <= 1.0:
        raise SimdiffError(f"ballistic strength must be in [0, 1], got {strength}")
    f, single, valid = batch_features(features, lengths, "ballistic flight")
    b, t = f.shape[:2]
    g = torch.as_tensor(gravity, dtype=torch.float64).reshape(-1).cpu()
    if g.numel() not in (1, b):
        raise SimdiffError(f"ballistic flight needs 1 or {b} gravity values, got {g.numel()}")
    bad = [float(v) for v in g if not torch.isfinite(v)]
    if bad:
        raise SimdiffError(f"ballistic flight needs a finite gravity, got {bad[0]}")
    g = g.expand(b)
    if strength == 0.0 or t < 3:
        return features.clone()
    joints = features_to_joints(f).cpu().numpy()  # (B, T, 22, 3)
    lens = valid.sum(dim=1).cpu().tolist()
    shift = np.zeros((b, t))
    for i in range(b):
        n = int(lens[i])
        if n < 3:
            continue
        spans = flights(joints[i, :n])
        shift[i, :n] = strength * parabola_shift(joints[i, :n, 0, 1], spans, float(g[i]), fps,
                                                 clearance=foot_clearance(joints[i, :n]))
    d = torch.from_numpy(shift).to(f)
    f[..., SLICES["root_y"]] += d[..., None]
    f[..., RIC_Y] += d[..., None]
    step = (d[:, 1:] - d[:, :-1]) * valid[:, 1:]  # velocity row r is the step r -> r + 1
    f[:, :-1, VEL_Y] += step[..., None]
    out = f.to(features.dtype)
    return out[0] if single else out
