"""Timelines (``simdiff generate --timeline FILE.json``): several prompts in a row, each under its own φ, as one
motion of any length.

The file (checked by :func:`simdiff.product.request.read_timeline`) is a JSON list of segments ``{"text": str,
"seconds": number, "gravity"?: number, "wind"?: [x, y]}``. The first segment is sampled as ``generate`` samples one
prompt; each next one continues from the last :data:`CONTEXT_FRAMES` frames written so far,
given as keyframes (:func:`simdiff.inference.keyframes.sample_keyframed`), so the seam carries the motion on. Cost
is one sample per segment: linear in the total length.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass

import numpy as np

from simdiff.motion.skeleton import MAX_FRAMES
from simdiff.sim.env import Environment

CONTEXT_FRAMES: int = 10
"""Frames (0.5 s) of the motion so far that each next segment continues from."""
MAX_SEGMENT_FRAMES: int = MAX_FRAMES - CONTEXT_FRAMES
"""A segment's longest own part: the network's 196 frames less the context."""


@dataclass(frozen=True)
class Segment:
    """One prompt of a timeline: its text, its own frames at 20 fps and its environment φ."""

    text: str
    frames: int
    env: Environment


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
