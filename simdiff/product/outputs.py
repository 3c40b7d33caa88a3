"""Files ``simdiff generate`` writes: joints/features ``.npy``, BVH, glTF (``.glb``), stick video and
``generation.json``."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Callable, Iterable, Sequence

import numpy as np

from simdiff.errors import SimdiffError
from simdiff.fsio import ensure_dir, save_npy, write_json
from simdiff.motion.skeleton import FPS

Progress = Callable[[Iterable, int, str], Iterable]
"""``progress(iterable, total, description) -> iterable``: wraps a loop (e.g. in tqdm)."""


def slug(text: str, max_len: int = 40) -> str:
    """A file-name-safe short form of a prompt: ``"A person jumps!"`` → ``"a_person_jumps"``."""
    s = re.sub(r"[^a-z0-9]+", "_", text.lower()).strip("_")[:max_len].rstrip("_")
    return s or "motion"


def env_label(value: float) -> str:
    """A compact, file-name-safe number: ``-3.7`` → ``"-3.7"``, ``2.0`` → ``"2"``."""
    return f"{value:g}"


def fresh_dir(path: Path) -> Path:
    """``path`` if it is absent or an empty folder, else the first free ``path-2``, ``path-3``, ...

    Default output folders never mix or overwrite earlier runs; an explicit ``--out`` is used as given.
    """
    def taken(p: Path) -> bool:
        return p.exists() and (not p.is_dir() or any(p.iterdir()))

    if not taken(path):
        return path
    n = 2
    while taken(path.with_name(f"{path.name}-{n}")):
        n += 1
    return path.with_name(f"{path.name}-{n}")


def prepare_out_dir(path: Path) -> Path:
    """Create the output folder; a path that exists and is not a folder raises."""
    if path.exists() and not path.is_dir():
        raise SimdiffError(f"--out {str(path)!r} exists and is not a folder")
    return ensure_dir(path)


def write_motion(stem: Path, joints: np.ndarray, features: np.ndarray, formats: Sequence[str],
                 fps: float = FPS) -> dict[str, Path]:
    """Write one motion next to ``stem`` (a path without suffix).

    Args:
        stem: e.g. ``out/sample0`` → ``sample0_joints.npy``, ``sample0_features.npy``, ``sample0.bvh``,
            ``sample0.glb``.
        joints: (T, 22, 3) float32 positions in metres, Y-up.
        features: (T, 263) float32 un-normalised HumanML3D features (one row per joint frame).
        formats: kinds to write; ``npy`` (joints + features), ``bvh`` and ``glb`` (skinned body on the motion's
            own mean skeleton, :func:`simdiff.motion.rigid.fit`) are handled here.
    Returns:
        kind → written path (``joints``, ``features``, ``bvh``, ``glb``).
    """
    written: dict[str, Path] = {}
    if "npy" in formats:
        written["joints"] = stem.with_name(stem.name + "_joints.npy")
        save_npy(written["joints"], np.asarray(joints, dtype=np.float32))
        written["features"] = stem.with_name(stem.name + "_features.npy")
        save_npy(written["features"], np.asarray(features, dtype=np.float32))
    if "bvh" in formats:
        from simdiff.motion.io.bvh_writer import write_bvh

        written["bvh"] = write_bvh(stem.with_name(stem.name + ".bvh"), joints, fps=fps)
    if "glb" in formats:
        from simdiff.motion.io.gltf_writer import write_glb
        from simdiff.motion.rigid import fit

        written["glb"] = write_glb(stem.with_name(stem.name + ".glb"), fit(joints, None), fps=fps)
    return written


def render_video(motions: Sequence[np.ndarray], captions: Sequence[str], path: Path, fps: float = FPS,
                 progress: Progress | None = None) -> Path:
    """Render (T, 22, 3) motions side by side to ``path`` (``.gif`` or ``.mp4``).

    Frames come from the stick renderer (:func:`simdiff.viz.stick.animation_frames`); GIFs go through the
    shared-palette writer (:func:`simdiff.viz.video.write_gif`), MP4s through H.264; both atomically.
    """
    from simdiff.viz.stick import animation_frames

    suffix = path.suffix.lower()
    if suffix not in (".gif", ".mp4"):
        raise SimdiffError(f"unsupported video suffix {suffix!r} in {str(path)!r}; use .gif or .mp4")
    frames: Iterable[np.ndarray] = animation_frames(list(motions), list(captions), fps)
    if progress is not None:
        frames = progress(frames, max(int(m.shape[0]) for m in motions), f"rendering {suffix[1:]}")
    from simdiff.viz.video import write_video

    write_video(frames, path, fps)
    return path


def write_metadata(path: Path, data: dict) -> Path:
    """Write ``data`` as indented JSON atomically (non-finite floats are refused)."""
    return write_json(path, data, indent=2, allow_nan=False)
