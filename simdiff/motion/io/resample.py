"""Frame-rate conversion of motion arrays with an anti-aliasing low-pass filter."""

from __future__ import annotations

from fractions import Fraction

import numpy as np

from simdiff.motion.io.rates import check_fps

_MAX_FACTOR = 64
"""Largest up/down factor handled by polyphase filtering; other ratios interpolate."""


def _rational_ratio(src_fps: float, dst_fps: float) -> tuple[int, int] | None:
    """(up, down) with dst/src == up/down to 0.1 %, or None for an awkward ratio."""
    ratio = Fraction(dst_fps / src_fps).limit_denominator(_MAX_FACTOR)
    if ratio.numerator > _MAX_FACTOR or ratio.numerator == 0:
        return None
    if abs(float(ratio) * src_fps - dst_fps) > 1e-3 * dst_fps:
        return None
    return ratio.numerator, ratio.denominator


def frames_at(frames: np.ndarray, at: np.ndarray) -> np.ndarray:
    """(N, ...) float64: ``frames`` (F, ...) linearly interpolated at fractional indices ``at`` (N,) in [0, F − 1]."""
    f = np.asarray(frames, dtype=np.float64)
    i0 = np.clip(np.floor(at).astype(int), 0, len(f) - 1)
    i1 = np.minimum(i0 + 1, len(f) - 1)
    w = (at - i0).reshape(-1, *([1] * (f.ndim - 1)))
    return (1.0 - w) * f[i0] + w * f[i1]


def resample(positions: np.ndarray, src_fps: float, dst_fps: float = 20.0) -> np.ndarray:
    """Resample a motion along its first (time) axis from ``src_fps`` to ``dst_fps``.

    Rational ratios (30->20, 60->20, 120->20, 25->20, ...) use polyphase filtering
    (``scipy.signal.resample_poly``: a Kaiser-windowed FIR low-pass at the lower Nyquist
    rate, then decimation) on the motion extended at both ends by odd reflection, so the
    first and last frames neither droop nor ring. Other ratios low-pass with a zero-phase
    Butterworth filter (cut-off at 0.8 x the target Nyquist rate) before cubic-spline
    interpolation at the new times. Frame 0 stays at time 0 and the output covers the
    input duration.

    Args:
        positions: (T, ...) array, e.g. (T, J, 3) joint positions in metres.
        src_fps: frame rate of ``positions`` (frames per second).
        dst_fps: wanted frame rate.
    Returns:
        (T', ...) float32 array, T' = ceil(T * dst_fps / src_fps).
    Raises:
        FrameRateError: a rate that is not a finite number in [1, 1000] Hz (a ``SimdiffError``
            and a ``ValueError``; :func:`~simdiff.motion.io.rates.check_fps`).
    """
    src_fps = check_fps(src_fps, "source frame rate")
    dst_fps = check_fps(dst_fps, "target frame rate")
    x = np.asarray(positions, dtype=np.float64)
    if x.shape[0] == 0:
        return x.astype(np.float32)
    if abs(src_fps - dst_fps) <= 1e-6 * dst_fps:
        return x.astype(np.float32)
    n_out = int(np.ceil(x.shape[0] * dst_fps / src_fps - 1e-9))
    if x.shape[0] < 2:
        return np.repeat(x, n_out, axis=0).astype(np.float32)
    ratio = _rational_ratio(src_fps, dst_fps)
    if ratio is not None:
        out = _polyphase(x, *ratio)
    else:
        out = _filter_and_interpolate(x, src_fps, dst_fps, n_out)
    return np.ascontiguousarray(out[:n_out], dtype=np.float32)


def _polyphase(x: np.ndarray, up: int, down: int) -> np.ndarray:
    """``resample_poly`` on x padded by odd reflection (value and slope kept at the ends)."""
    from scipy import signal  # lazy: scipy.signal costs ~0.6 s to import

    half = 10 * max(up, down) / up + 2  # FIR half-length in input samples, plus margin
    blocks = min(int(np.ceil(half / down)), (x.shape[0] - 2) // down)
    pad = blocks * down
    if blocks <= 0:
        return signal.resample_poly(x, up, down, axis=0, padtype="line")
    head = 2.0 * x[:1] - x[pad:0:-1]
    tail = 2.0 * x[-1:] - x[-2 : -pad - 2 : -1]
    padded = np.concatenate([head, x, tail], axis=0)
    out = signal.resample_poly(padded, up, down, axis=0, padtype="line")
    return out[blocks * up :]


def _filter_and_interpolate(
    x: np.ndarray, src_fps: float, dst_fps: float, n_out: int
) -> np.ndarray:
    """Butterworth low-pass (when decimating) then cubic-spline sampling at dst times."""
    from scipy import signal
    from scipy.interpolate import CubicSpline

    if dst_fps < src_fps:
        cutoff = 0.8 * (dst_fps / 2.0) / (src_fps / 2.0)
        sos = signal.butter(4, cutoff, output="sos")
        padlen = min(x.shape[0] - 1, 3 * 2 * len(sos))
        if padlen > 0:
            x = signal.sosfiltfilt(sos, x, axis=0, padtype="odd", padlen=padlen)
    t_src = np.arange(x.shape[0]) / src_fps
    t_dst = np.arange(n_out) / dst_fps
    t_dst = np.minimum(t_dst, t_src[-1])
    return CubicSpline(t_src, x, axis=0)(t_dst)
