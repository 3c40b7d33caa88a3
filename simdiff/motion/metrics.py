"""Physics plausibility metrics on joint positions (CLoSD's joint-based protocol).

Joints are HumanML3D positions in metres, Y-up, ground plane y = 0, 20 fps. With
``h_t = min_j y_j(t)`` the lowest joint of frame t (all 22 joints, no mesh):

* penetration (mm): ``max(0, -(h_t + 0.005)) * 1000``, per valid frame;
* floating (mm): ``max(0, h_t - 0.005) * 1000``, per valid frame;
* sliding (mm/frame): for t = 0..len-2 with ``c = argmin_j y_j(t)``, the xz displacement
  ``|xz_c(t+1) - xz_c(t)| * 1000`` if ``y_c(t) <= 0.005`` and ``y_c(t+1) <= 0.005``, else 0;
* skate_ratio (GMD): fraction of frame pairs in which foot joint 10 or 11 is below 0.05 m in
  both frames and moves faster than 0.5 m/s in xz, both at that pair and in the 5-pair
  centred moving average (zeros beyond the valid span: scipy ``uniform_filter1d`` mode
  'constant', :func:`centred_mean`).

Aggregation as in CLoSD: penetration, floating and sliding are means over all valid frames
(frame pairs for sliding) of all samples pooled; skate_ratio is the mean of per-sample ratios.
"""

from __future__ import annotations

from collections.abc import Sequence

import sys
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    import torch

from simdiff.errors import SimdiffError
from simdiff.motion.skeleton import FOOT_LEFT, FOOT_RIGHT, FPS, NUM_JOINTS

GROUND_TOLERANCE: float = 0.005
"""Metres of slack for penetration, floating and sliding contact (5 mm)."""
SKATE_FEET: tuple[int, int] = (10, 11)
"""Left and right foot (toe) joints used by the GMD skate ratio."""
SKATE_HEIGHT: float = 0.05
"""Metres: a foot below this in two consecutive frames is in contact."""
SKATE_SPEED: float = 0.5
"""Metres per second of xz foot speed above which a contact foot skates."""
SKATE_WINDOW: int = 5
"""Frame pairs in the centred moving average of the foot speed."""

METRIC_NAMES: tuple[str, ...] = ("penetration", "floating", "sliding", "skate_ratio")


def _as_numpy(value: object) -> object:
    """A torch tensor as a numpy array (torch is not imported here: a tensor implies it is loaded)."""
    torch = sys.modules.get("torch")
    if torch is not None and isinstance(value, torch.Tensor):
        return value.detach().cpu().numpy()
    return value


def _prepare(
    joints: np.ndarray | torch.Tensor, lengths: Sequence[int] | np.ndarray | torch.Tensor | None
) -> tuple[np.ndarray, np.ndarray]:
    """(B, T, 22, 3) float array and (B,) int64 lengths, validated."""
    arr = np.asarray(_as_numpy(joints))
    if arr.ndim not in (3, 4) or arr.shape[-2:] != (NUM_JOINTS, 3):
        raise SimdiffError(f"joints must have shape (B, T, 22, 3) or (T, 22, 3), got {arr.shape}")
    if arr.ndim == 3:
        arr = arr[None]
    if not np.issubdtype(arr.dtype, np.floating) or arr.dtype == np.float16:
        arr = arr.astype(np.float32)
    batch, frames = arr.shape[:2]
    if frames < 2:
        raise SimdiffError(f"joints need at least 2 frames, got {frames}")
    if lengths is None:
        lens = np.full(batch, frames, dtype=np.int64)
    else:
        lens = np.asarray(_as_numpy(lengths)).reshape(-1)
        if lens.shape != (batch,):
            raise SimdiffError(f"lengths must have {batch} entries, got {lens.shape[0]}")
        if not np.issubdtype(lens.dtype, np.integer):
            raise SimdiffError(f"lengths must be integers, got dtype {lens.dtype}")
        lens = lens.astype(np.int64)
        bad = np.flatnonzero((lens < 2) | (lens > frames))
        if bad.size:
            i = int(bad[0])
            raise SimdiffError(f"lengths[{i}]={lens[i]} is outside [2, {frames}]")
    return arr, lens


def _per_sample(arr: np.ndarray, lens: np.ndarray) -> dict[str, np.ndarray]:
    """Per-sample sums and counts; see per_sample_physics_metrics."""
    batch, frames = arr.shape[:2]
    t = np.arange(frames)
    frame_mask = t[None, :] < lens[:, None]  # (B, T)
    pair_mask = t[None, :-1] < (lens[:, None] - 1)  # (B, T-1)

    heights = arr[..., 1]  # (B, T, 22)
    lowest_idx = heights.argmin(axis=-1)  # (B, T)
    lowest = np.take_along_axis(heights, lowest_idx[..., None], axis=-1)[..., 0]  # (B, T)

    penetration = np.maximum(0.0, -(lowest.astype(np.float64) + GROUND_TOLERANCE)) * 1000.0
    floating = np.maximum(0.0, lowest.astype(np.float64) - GROUND_TOLERANCE) * 1000.0

    # Sliding: the lowest joint at t, followed into t+1.
    idx = lowest_idx[:, :-1, None, None]  # (B, T-1, 1, 1)
    now = np.take_along_axis(arr[:, :-1], idx, axis=2)[:, :, 0]  # (B, T-1, 3)
    nxt = np.take_along_axis(arr[:, 1:], idx, axis=2)[:, :, 0]
    contact = (now[..., 1] <= GROUND_TOLERANCE) & (nxt[..., 1] <= GROUND_TOLERANCE) & pair_mask
    step = np.hypot(
        nxt[..., 0].astype(np.float64) - now[..., 0], nxt[..., 2].astype(np.float64) - now[..., 2]
    )
    sliding = np.where(contact, step * 1000.0, 0.0)

    n_frames = lens.astype(np.float64)
    n_pairs = n_frames - 1.0
    return {
        "penetration": np.where(frame_mask, penetration, 0.0).sum(axis=1) / n_frames,
        "floating": np.where(frame_mask, floating, 0.0).sum(axis=1) / n_frames,
        "sliding": sliding.sum(axis=1) / n_pairs,
        "skate_ratio": _skating(arr, pair_mask).sum(axis=1) / n_pairs,
    }


def _skating(arr: np.ndarray, pair_mask: np.ndarray) -> np.ndarray:
    """(B, T-1) bool: GMD skating of either foot between frames t and t+1."""
    feet = arr[:, :, list(SKATE_FEET)].astype(np.float64)  # (B, T, 2, 3)
    step = feet[:, 1:] - feet[:, :-1]
    speed = np.hypot(step[..., 0], step[..., 2]) * FPS  # (B, T-1, 2) m/s
    speed = np.where(pair_mask[..., None], speed, 0.0)
    avg = centred_mean(speed, SKATE_WINDOW)
    low = feet[..., 1] < SKATE_HEIGHT  # (B, T, 2)
    contact = low[:, :-1] & low[:, 1:]
    skating = contact & (speed > SKATE_SPEED) & (avg > SKATE_SPEED) & pair_mask[..., None]
    return skating.any(axis=-1)


def centred_mean(x: np.ndarray, size: int) -> np.ndarray:
    """Moving average of odd ``size`` along axis 1, centred, zeros beyond both ends.

    The same as ``scipy.ndimage.uniform_filter1d(x, size, axis=1, mode="constant", cval=0.0)``
    without importing ``scipy.ndimage`` (about 0.3 s, a sixth of a simulated finish's budget).
    """
    if size < 1 or size % 2 == 0:
        raise SimdiffError(f"centred_mean needs an odd window, got {size}")
    half = size // 2
    pad = [(0, 0)] * x.ndim
    pad[1] = (half + 1, half)
    c = np.cumsum(np.pad(np.asarray(x, dtype=np.float64), pad), axis=1)
    n = x.shape[1]
    return (np.take(c, np.arange(size, size + n), axis=1) - np.take(c, np.arange(n), axis=1)) / size


def per_sample_physics_metrics(
    joints: np.ndarray | torch.Tensor,
    lengths: Sequence[int] | np.ndarray | torch.Tensor | None = None,
) -> dict[str, np.ndarray]:
    """Physics metrics of each sample.

    Args:
        joints: (B, T, 22, 3) or (T, 22, 3) positions in metres, Y-up, ground y = 0.
        lengths: (B,) valid frames per sample, each in [2, T]; None means all T.
    Returns:
        {"penetration", "floating" (mm, mean over the sample's frames), "sliding" (mm per
        frame, mean over its len-1 frame pairs), "skate_ratio" (fraction of its pairs)},
        each a (B,) float64 array.
    """
    arr, lens = _prepare(joints, lengths)
    return _per_sample(arr, lens)


def physics_metrics(
    joints: np.ndarray | torch.Tensor,
    lengths: Sequence[int] | np.ndarray | torch.Tensor | None = None,
) -> dict[str, float]:
    """Physics metrics of a batch, aggregated as CLoSD does.

    Args:
        joints: (B, T, 22, 3) or (T, 22, 3) positions in metres, Y-up, ground y = 0.
        lengths: (B,) valid frames per sample, each in [2, T]; None means all T.
    Returns:
        {"penetration", "floating"} in mm averaged over all valid frames of all samples,
        "sliding" in mm/frame averaged over all valid frame pairs, and "skate_ratio" as the
        mean of the per-sample ratios.
    """
    arr, lens = _prepare(joints, lengths)
    per = _per_sample(arr, lens)
    n_frames = lens.astype(np.float64)
    n_pairs = n_frames - 1.0
    return {
        "penetration": float((per["penetration"] * n_frames).sum() / n_frames.sum()),
        "floating": float((per["floating"] * n_frames).sum() / n_frames.sum()),
        "sliding": float((per["sliding"] * n_pairs).sum() / n_pairs.sum()),
        "skate_ratio": float(per["skate_ratio"].mean()),
    }


OWN_FLOOR_PERCENTILE: float = 5.0
"""Percentile of a motion's per-frame lowest-joint height taken as its own floor (see :func:`own_floor_metrics`)."""


def own_floor_metrics(
    joints: np.ndarray | torch.Tensor,
    lengths: Sequence[int] | np.ndarray | torch.Tensor | None = None,
) -> dict[str, float]:
    """Sliding measured on each motion's own floor, and how far that floor is from y = 0.

    CLoSD's sliding counts a lowest joint as in contact only within 5 mm of y = 0, so a motion
    that hovers (its stance feet 2 cm up) scores 0 sliding however much its feet skate: the
    metric is vacuous there, and Phys-Err rewards hovering as floating-to-GT once rewarded
    sinking. Here every motion is first shifted so that its own floor, the
    :data:`OWN_FLOOR_PERCENTILE`-th percentile of its lowest-joint height over its valid frames,
    is at y = 0; then the same sliding is taken. On motion that stands on y = 0 the two agree.

    Args:
        joints: (B, T, 22, 3) or (T, 22, 3) metres, Y-up; lengths: (B,) valid frames (None: all).
    Returns:
        {"sliding_own_floor": mm/frame pooled over all valid frame pairs as :func:`physics_metrics`,
         "own_floor": mean over samples of the own floor's height above y = 0 (mm; negative below)}.
    """
    arr, lens = _prepare(joints, lengths)
    lowest = arr[..., 1].min(axis=-1).astype(np.float64)  # (B, T)
    floor = np.array([np.percentile(lowest[b, : lens[b]], OWN_FLOOR_PERCENTILE) for b in range(len(lens))])
    shifted = arr.astype(np.float64, copy=True)
    shifted[..., 1] -= floor[:, None, None]
    return {"sliding_own_floor": physics_metrics(shifted, lens)["sliding"], "own_floor": float(floor.mean() * 1000.0)}


FLOOR_CLEARANCE: float = 0.10
"""Metres: a motion whose lowest joint stays higher than this in every valid frame never touches the floor."""


def never_touches(
    joints: np.ndarray | torch.Tensor,
    lengths: Sequence[int] | np.ndarray | torch.Tensor | None = None,
    clearance: float = FLOOR_CLEARANCE,
) -> np.ndarray:
    """(B,) bool: the motion's lowest joint stays more than ``clearance`` m above y = 0 in every valid frame.

    The floor is y = 0, not the motion's own floor: a sample that hovers a metre up all clip long has a
    perfect own-floor gait and flights by the relative rule of :mod:`simdiff.motion.flight`, yet no
    body part ever reaches the ground (generated runs under g = −1.6 with strong environment
    guidance). Real motion under any gravity touches the floor to take off. Joints (B, T, 22, 3) or (T, 22, 3), metres, Y-up; lengths (B,).
    """
    arr, lens = _prepare(joints, lengths)
    lowest = arr[..., 1].min(axis=-1)  # (B, T)
    valid = np.arange(arr.shape[1])[None, :] < lens[:, None]
    return np.where(valid, lowest, np.inf).min(axis=1) > clearance


def floating_to_gt(
    joints: np.ndarray | torch.Tensor,
    gt_joints: np.ndarray | torch.Tensor,
    lengths: Sequence[int] | np.ndarray | torch.Tensor | None = None,
    gt_lengths: Sequence[int] | np.ndarray | torch.Tensor | None = None,
) -> float:
    """Floating scored as PhysDiff's table marks it ('→', closer to ground truth is better).

    ``|floating(joints) − floating(gt_joints)|`` in mm, each the CLoSD pooled mean. Real motion
    floats too (a lowest joint above 5 mm in flight and on tiptoe), so a motion that sinks into
    the floor must not score better than the ground truth: with this term it scores worse.

    Args:
        joints, gt_joints: (B, T, 22, 3) or (T, 22, 3) metres, Y-up; the generated motions and the
            ground-truth motions of the same captions (batches may differ in size and length).
        lengths, gt_lengths: valid frames per sample (None: all).
    """
    gen = physics_metrics(joints, lengths)["floating"]
    ref = physics_metrics(gt_joints, gt_lengths)["floating"]
    return float(abs(gen - ref))


def phys_err(metrics: dict[str, float], gt_floating: float) -> float:
    """Our Phys-Err (mm): penetration + sliding + |floating − floating of the ground truth|.

    PhysDiff's sum adds raw floating, which rewards sinking; we replace it by the distance to the
    ground truth's floating (see :func:`floating_to_gt`). ``metrics`` holds penetration, floating
    and sliding (:func:`physics_metrics`); sliding is mm/frame, counted as mm as PhysDiff does.
    """
    missing = [k for k in ("penetration", "floating", "sliding") if k not in metrics]
    if missing:
        raise SimdiffError(f"phys_err needs {', '.join(missing)}")
    return float(metrics["penetration"] + metrics["sliding"] + abs(metrics["floating"] - gt_floating))


GLIDE_SPEED: float = 0.5
"""m/s: a motion whose pelvis travels faster than this on average (horizontal) is moving somewhere."""
GLIDE_LIFT: float = 0.05
"""Metres: a foot joint whose height changes by less than this over the clip never lifts."""


def glides(
    joints: np.ndarray | torch.Tensor,
    lengths: Sequence[int] | np.ndarray | torch.Tensor | None = None,
) -> np.ndarray:
    """(B,) bool: the body travels (mean horizontal pelvis speed > :data:`GLIDE_SPEED`) while no foot joint ever
    lifts (each of the four foot joints' height range over the valid frames < :data:`GLIDE_LIFT`).

    A frozen pose carried along, which no legged body can do; generated runs under g = −1.6 at environment
    guidance 4 were such statues: a metre up, and skating once the foot cleanup dropped them onto the floor. A standing or
    in-place motion (slow pelvis) never glides. Joints (B, T, 22, 3) or (T, 22, 3), metres, Y-up, 20 fps; lengths (B,).
    """
    arr, lens = _prepare(joints, lengths)
    out = np.zeros(len(lens), dtype=bool)
    feet = [*FOOT_LEFT, *FOOT_RIGHT]
    for b, n in enumerate(lens):
        clip = arr[b, :n].astype(np.float64)
        speed = np.linalg.norm(np.diff(clip[:, 0, [0, 2]], axis=0), axis=-1).mean() * FPS
        lift = np.ptp(clip[:, feet, 1], axis=0).max()
        out[b] = speed > GLIDE_SPEED and lift < GLIDE_LIFT
    return out
