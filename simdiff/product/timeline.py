"""Timelines (``simdiff generate --timeline FILE.json``): several prompts in a row, each under its own φ, as one
motion of any length.

The file is a JSON list of segments ``{"text": str, "seconds": number, "gravity"?: number, "wind"?: [x, y]}``. The
first segment is sampled as ``generate`` samples one prompt; each next one continues from the last
:data:`CONTEXT_FRAMES` frames written so far, given as keyframes (:func:`simdiff.inference.keyframes.sample_keyframed`),
so the seam carries the motion on. Cost is one sample per segment: linear in the total length.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from simdiff.errors import SimdiffError
from simdiff.motion.skeleton import FPS, MAX_FRAMES, MIN_GENERATE_FRAMES
from simdiff.sim.env import EARTH_GRAVITY, Environment

CONTEXT_FRAMES: int = 10
"""Frames (0.5 s) of the motion so far that each next segment continues from."""
MAX_SEGMENT_FRAMES: int = MAX_FRAMES - CONTEXT_FRAMES
"""A segment's longest own part: the network's 196 frames less the context."""
MAX_SEGMENTS: int = 100
"""Most segments in one timeline."""
KEYS: frozenset[str] = frozenset({"text", "seconds", "gravity", "wind"})


@dataclass(frozen=True)
class Segment:
    """One prompt of a timeline: its text, its own frames at 20 fps and its environment φ."""

    text: str
    frames: int
    env: Environment


def read_timeline(path: str | Path, force: bool = False) -> tuple[Segment, ...]:
    """The checked segments of a timeline file; one line naming the file, the segment and the bad value otherwise.
    ``force`` widens the environment ranges as ``generate --force`` does."""
    path = Path(path)
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise SimdiffError(f"no timeline file {str(path)!r}") from None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise SimdiffError(f"{path}: not a JSON timeline ({exc})") from None
    return parse_timeline(data, str(path), force)


def parse_timeline(data: Any, name: str = "the timeline", force: bool = False) -> tuple[Segment, ...]:
    """:func:`read_timeline` for parsed JSON: a non-empty list of segment objects."""
    from simdiff.product.request import check_finite, check_text

    if not isinstance(data, list) or not data:
        raise SimdiffError(f"{name} must be a non-empty JSON list of segments "
                           '[{"text": ..., "seconds": ..., "gravity"?: ..., "wind"?: [x, y]}, ...]')
    if len(data) > MAX_SEGMENTS:
        raise SimdiffError(f"{name} has {len(data)} segments; the most is {MAX_SEGMENTS}")
    segments = []
    for i, seg in enumerate(data):
        where = f"{name}: segment {i}"
        if not isinstance(seg, dict):
            raise SimdiffError(f"{where} is {type(seg).__name__}, not an object with text and seconds")
        unknown = sorted(set(seg) - KEYS)
        if unknown:
            raise SimdiffError(f"{where} has an unknown key {unknown[0]!r}; use text, seconds, gravity, wind")
        for key in ("text", "seconds"):
            if key not in seg:
                raise SimdiffError(f"{where} has no {key!r}")
        if not isinstance(seg["text"], str):
            raise SimdiffError(f"{where}: text must be a string, got {seg['text']!r}")
        try:
            text = check_text(seg["text"])
            seconds = check_finite(f"{where}: seconds", _number(seg["seconds"], f"{where}: seconds"))
            gravity = check_finite(f"{where}: gravity", _number(seg.get("gravity", EARTH_GRAVITY), f"{where}: gravity"))
            wind = seg.get("wind", [0.0, 0.0])
            if not isinstance(wind, list) or len(wind) != 2:
                raise SimdiffError(f"{where}: wind must be [x, y] in newtons, got {wind!r}")
            wx, wy = (check_finite(f"{where}: wind", _number(w, f"{where}: wind")) for w in wind)
            env = Environment(gravity, wx, wy).validate(force)
        except SimdiffError as exc:
            message = str(exc)
            raise SimdiffError(message if message.startswith(where) else f"{where}: {message}") from None
        frames = round(seconds * FPS)
        low = MIN_GENERATE_FRAMES if i == 0 else 1
        if not low <= frames <= (MAX_FRAMES if i == 0 else MAX_SEGMENT_FRAMES):
            top = (MAX_FRAMES if i == 0 else MAX_SEGMENT_FRAMES) / FPS
            raise SimdiffError(f"{where}: seconds {seconds:g} is outside {low / FPS:g}..{top:g} (one segment is one "
                               "network window; split longer ones)")
        segments.append(Segment(text, frames, env))
    return tuple(segments)


def _number(value: Any, name: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise SimdiffError(f"{name} must be a number, got {value!r}")
    return float(value)


def segment_seed(seed: int, index: int) -> int:
    """Segment ``index``'s noise seed for a sample with ``seed`` (distinct from the other samples' seeds)."""
    return (seed * 1_000_003 + index) % 2**63


def sample_timeline(generator, segments: tuple[Segment, ...], config, *, seed: int = 0,
                    progress: Callable[[Iterable], Iterable] | None = None) -> tuple[np.ndarray, np.ndarray]:
    """One motion through every segment: (features (T, 263) of the whole motion, joints (T, 22, 3)), float32,
    T = the segments' frames summed. ``generator``: a continuous SimDiff or backbone-only
    :class:`~simdiff.inference.generator.MotionGenerator` (the latter ignores φ)."""
    from simdiff.inference.keyframes import sample_keyframed
    from simdiff.motion.features import process_joints
    from simdiff.motion.rigid import joints_from_features

    texts = sorted({s.text for s in segments})
    embedded = dict(zip(texts, generator.encode_text(texts)))
    joints = np.zeros((0, 22, 3), dtype=np.float32)
    for i, seg in enumerate(segments):
        env = seg.env.as_tuple() if generator.is_simdiff else None
        emb = embedded[seg.text][None]
        if i == 0:
            out = generator.generate([seg.text], seg.frames, config, env=env, seed=segment_seed(seed, i),
                                     text_embeddings=emb, progress=progress)
            joints = joints_from_features(out.clips()[0].cpu().numpy(), config.foot_lock)
            continue
        keys = np.full((CONTEXT_FRAMES + seg.frames, 22, 3), np.nan)
        keys[:CONTEXT_FRAMES] = joints[-CONTEXT_FRAMES:]
        _, part = sample_keyframed(generator, keys, config, text_embeddings=emb, env=env,
                                   seed=segment_seed(seed, i), progress=progress)
        joints = np.concatenate([joints[:-CONTEXT_FRAMES], part]).astype(np.float32)
    features = process_joints(joints).features
    return np.concatenate([features, features[-1:]]).astype(np.float32), joints


def spans(segments: tuple[Segment, ...]) -> list[tuple[int, int]]:
    """Each segment's ``[start, end)`` frames in the timeline's motion."""
    ends = np.cumsum([s.frames for s in segments])
    return [(int(e - s.frames), int(e)) for s, e in zip(segments, ends)]
