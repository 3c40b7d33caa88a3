"""Looped locomotion clips: a short cyclic walk or run repeated to a longer clip (``simdiff data loop``).

Why: every train clip of the all-source corpus captioned "a person runs forward." is 40-75 frames long (2-3.75 s;
capture volumes are small), while its only runs of 96-150 frames are elderly or weary ones (1.35-1.94 m/s). The
8-layer model samples a 6 s "runs forward" at about 1.4-1.5 m/s instead of the plain runs' 2.65; a likely cause is
that it never saw a plain run that long. A looped clip shows it one, at the speed the capture had.

How: :func:`find_period` finds a start s and a lag whose pose (root-relative, in the heading frame) best repeats
the frames from s, among the periods that move at the clip's own speed; :func:`loop_joints` repeats frames
``[s, s + period)`` with the rigid yaw + horizontal move the body made over one period, each copy cross-faded from
the capture's own continuation. All positions in metres, Y-up, 20 fps,
(frames, 22, 3).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from simdiff.errors import SimdiffError
from simdiff.motion.kinematics import facing_direction
from simdiff.motion.skeleton import FACE_JOINTS, FPS

MIN_PERIOD: int = 10
"""Shortest period tried (frames; 0.5 s: a run's stride, two steps, takes about 0.6-0.7 s)."""
MATCH_FRAMES: int = 5
"""Frames compared at the start of the clip and after the lag."""
BLEND_FRAMES: int = 3
"""Frames over which each copy fades in from the capture's continuation."""


MIN_SPEED: float = 0.2
"""Clips slower than this (m/s) are not looped: a still pose repeats at any lag."""
SPEED_TOLERANCE: float = 0.15
"""A period's mean horizontal root speed must lie within this fraction of the whole clip's (so that a run which
starts from standing is not looped from its standing frames, which repeat at any lag)."""


@dataclass(frozen=True)
class Period:
    """A clip's period: ``frames`` from frame ``start``, and the mean joint distance (m) of its match (``error``)."""

    start: int
    frames: int
    error: float


def _yaw(joints: np.ndarray) -> np.ndarray:
    """(T,) heading angle about +Y (rad; 0 = facing +Z) of (T, 22, 3) joints."""
    forward = facing_direction(joints, FACE_JOINTS)
    return np.arctan2(forward[:, 0], forward[:, 2])


def _rot_y(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def _local(joints: np.ndarray) -> np.ndarray:
    """Joints relative to the frame's root on the ground plane, turned so each frame faces +Z."""
    yaw = _yaw(joints)
    rel = joints - joints[:, :1] * np.array([1.0, 0.0, 1.0])
    c, s = np.cos(-yaw)[:, None], np.sin(-yaw)[:, None]
    x, z = rel[..., 0], rel[..., 2]
    return np.stack([c * x + s * z, rel[..., 1], -s * x + c * z], axis=-1)


def _path(joints: np.ndarray) -> np.ndarray:
    """(T,) horizontal distance the root has travelled by each frame (m; 0 at frame 0)."""
    step = np.linalg.norm(np.diff(joints[:, 0][:, [0, 2]], axis=0), axis=-1)
    return np.concatenate([[0.0], np.cumsum(step)])


def find_period(joints: np.ndarray, min_period: int = MIN_PERIOD, match: int = MATCH_FRAMES,
                blend: int = BLEND_FRAMES, tolerance: float = SPEED_TOLERANCE) -> Period:
    """The start s and lag k >= ``min_period`` whose frames ``[s + k, s + k + match)`` best repeat frames
    ``[s, s + match)`` (mean joint distance in the heading frame), leaving ``blend`` frames after s + k for the
    cross-fade, among the (s, k) whose frames ``[s, s + k]`` move within ``tolerance`` of the clip's mean speed.

    Raises:
        SimdiffError: the clip is too short to hold one lag, hardly moves, or no period moves at its speed.
    """
    x = np.asarray(joints, dtype=np.float64)
    if x.ndim != 3 or x.shape[1:] != (22, 3):
        raise SimdiffError(f"joints of shape {x.shape}: expected (frames, 22, 3)")
    tail = max(match, blend)
    if len(x) - tail < min_period:
        raise SimdiffError(f"{len(x)} frames: too short to find a period of at least {min_period} frames")
    local = _local(x)
    path = _path(x)
    whole = path[-1] / (len(x) - 1) * FPS
    if whole < MIN_SPEED:
        raise SimdiffError(f"the clip moves {whole:.2f} m/s (< {MIN_SPEED} m/s): nothing to loop")
    lags = np.arange(min_period, len(x) - tail + 1)
    errors = np.full((len(x) - tail - min_period + 1, len(lags)), np.inf)  # [start, lag index]
    for i, k in enumerate(lags):
        starts = np.arange(len(x) - tail - k + 1)
        speed = (path[starts + k] - path[starts]) / k * FPS
        per_frame = np.linalg.norm(local[k:] - local[:-k], axis=-1).mean(axis=1)  # (T - k,) mean over joints
        window = np.lib.stride_tricks.sliding_window_view(per_frame, match)[: len(starts)].mean(axis=1)
        errors[starts, i] = np.where(np.abs(speed - whole) <= tolerance * whole, window, np.inf)
    start, i = np.unravel_index(int(np.argmin(errors)), errors.shape)  # first minimum: earliest start, then lag
    if not np.isfinite(errors[start, i]):
        raise SimdiffError(f"no period of {len(x)} frames moves within {tolerance:.0%} of the clip's {whole:.2f} m/s")
    return Period(int(start), int(lags[i]), float(errors[start, i]))


def loop_joints(joints: np.ndarray, frames: int, period: int, blend: int = BLEND_FRAMES, start: int = 0) -> np.ndarray:
    """(frames, 22, 3) float32: frames ``[start, start + period)`` of (T, 22, 3) ``joints`` repeated, copy n moved by
    the rigid motion (yaw about the root, horizontal shift) from frame ``start`` to ``start + period`` applied n
    times; the first ``blend`` frames of each copy fade in from the previous copy's continuation.

    Raises:
        SimdiffError: the period leaves fewer than ``blend`` frames after it, or ``frames`` < 1.
    """
    x = np.asarray(joints, dtype=np.float64)
    if frames < 1 or start < 0 or not 1 <= period <= len(x) - start - blend - 1:
        raise SimdiffError(f"cannot loop {len(x)} frames with period {period} from frame {start} to {frames} frames")
    x = x[start:]
    yaw = _yaw(x)
    turn = _rot_y(float(yaw[period] - yaw[0]))
    ground = np.array([1.0, 0.0, 1.0])
    origin, target = x[0, 0] * ground, x[period, 0] * ground

    copies = [x[: period + blend]]  # copy n: frames [0, period + blend) moved n times (its tail: the continuation)
    while len(copies) * period < frames:
        copies.append((copies[-1] - origin) @ turn.T + target)
    out = np.concatenate([c[:period] for c in copies])[:frames]
    for n in range(1, len(copies)):
        for j in range(min(blend, frames - n * period)):
            w = (j + 1) / (blend + 1)
            out[n * period + j] = (1 - w) * copies[n - 1][period + j] + w * out[n * period + j]
    return out.astype(np.float32)


MAX_ERROR: float = 0.08
"""Clips whose best period match is worse than this (mean joint distance, m) are not looped."""
LOOPS_NAME: str = "loops.json"


@dataclass
class LoopResult:
    """What :func:`loop_corpus` wrote: ``looped`` records (id, loop_of, period, match_m, frames), ``skipped``
    (id, reason) and the split file."""

    looped: list[dict]
    skipped: list[tuple[str, str]]
    split_file: str


def loop_corpus(corpus: str | Path, types: Sequence[str], frames: int, split: str = "train",
                out_split: str = "", max_error: float = MAX_ERROR, progress: bool = False) -> LoopResult:
    """Write ``L<id>`` clips of ``frames`` feature rows into ``corpus`` for every clip of ``split`` (mirrors included)
    whose ``motion_type`` is in ``types``, that is shorter than ``frames`` and was not padded, and whose period
    matches within ``max_error``; then ``<out_split>.txt`` (``split``'s ids and the loops) and ``loops.json``.
    ``manifest.json``, the split files, ``Mean.npy`` and ``Std.npy`` are left as they are (the loops repeat train
    frames). Re-running rewrites the same bytes; files are written atomically.

    Raises:
        SimdiffError: a missing manifest or split file, an unknown type, ``frames`` < 2.
    """
    from tqdm import tqdm

    from simdiff.data.clip_files import process_clip, write_clip
    from simdiff.data.writer import write_json, write_lines

    root = Path(corpus)
    out_split = out_split or f"{split}_loop"
    if frames < 2:
        raise SimdiffError(f"--frames must be >= 2, got {frames}")
    if "/" in out_split or out_split in ("train", "val", "test", "train_val", "all"):
        raise SimdiffError(f"--out-split {out_split!r}: choose a new split name (the corpus's own are kept)")
    from simdiff.data.manifest import LOOP_CLIP_KEYS, manifest_path, read_manifest

    manifest, split_path = manifest_path(root), root / f"{split}.txt"
    clips = {c["id"]: c for c in read_manifest(root, LOOP_CLIP_KEYS)["clips"]}
    if not split_path.is_file():
        raise SimdiffError(f"{split_path}: missing (a corpus of `simdiff data build`)")
    known = {c.get("motion_type") for c in clips.values()}
    if unknown := sorted(set(types) - known):
        raise SimdiffError(f"--types {' '.join(unknown)}: not a motion_type of {manifest} ({', '.join(sorted(map(str, known)))})")
    ids = split_path.read_text(encoding="utf-8").split()
    chosen = [i for i in ids if clips.get(i, {}).get("motion_type") in types]
    looped: list[dict] = []
    skipped: list[tuple[str, str]] = []
    for cid in tqdm(chosen, desc="loop", unit="clip", disable=not progress):
        clip = clips[cid]
        if int(clip["frames"]) >= frames:
            continue
        if clip.get("padded_frames"):
            skipped.append((cid, f"{clip['padded_frames']} held frames"))
            continue
        joints = np.load(root / "new_joints" / f"{cid}.npy")
        try:
            period = find_period(joints)
        except SimdiffError as exc:
            skipped.append((cid, str(exc)))
            continue
        if period.error > max_error:
            skipped.append((cid, f"period match {period.error:.3f} m > {max_error:g} m"))
            continue
        new = f"L{cid}"
        features, recovered = process_clip(new, loop_joints(joints, frames + 1, period.frames, start=period.start))
        lines = (root / "texts" / f"{cid}.txt").read_text(encoding="utf-8").splitlines()
        write_clip(root, new, features, recovered, lines)
        looped.append({"id": new, "loop_of": cid, "start": period.start, "period": period.frames, "match_m": round(period.error, 4),
                       "frames": int(features.shape[0]), "motion_type": clip["motion_type"]})
    write_lines(root / f"{out_split}.txt", ids + [r["id"] for r in looped])
    write_json(root / LOOPS_NAME, {"split": split, "out_split": out_split, "frames": frames, "types": list(types),
                                   "max_error_m": max_error, "looped": looped,
                                   "skipped": [{"id": i, "why": w} for i, w in skipped]})
    return LoopResult(looped, skipped, str(root / f"{out_split}.txt"))
