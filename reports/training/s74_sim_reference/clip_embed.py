"""Session 74's report scripts (cpp_floor.py, fid_split.py): HumanML3D-layout clips in evaluator 1's space.
Features are raw 263-d rows at 20 fps, cut to the evaluator's 196 frames and zero-padded."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import torch

MAX_FRAMES = 196


def load_clip(root: Path, key: str, frames: int = MAX_FRAMES) -> tuple[np.ndarray, int]:
    """((196, 263) float32 of the clip's first ``frames`` rows, zero-padded; the number of rows kept)."""
    x = np.load(root / "new_joint_vecs" / f"{key}.npy")[:frames].astype(np.float32)
    return np.pad(x, ((0, MAX_FRAMES - len(x)), (0, 0))), len(x)


def first_caption(root: Path, key: str) -> str:
    """The clip's first caption (HumanML3D texts/ line, tokens dropped)."""
    return (root / "texts" / f"{key}.txt").read_text().splitlines()[0].split("#")[0]


def embed_motions(ev, x: np.ndarray, lens: list[int], batch: int = 64) -> np.ndarray:
    """(N, 196, 263) features with their lengths → (N, D) motion embeddings, in batches."""
    return np.concatenate([ev.embed_motion(torch.from_numpy(x[i:i + batch]), lens[i:i + batch])
                           for i in range(0, len(x), batch)])


def embed_texts(ev, captions: list[str], batch: int = 64) -> np.ndarray:
    """(N,) captions → (N, D) text embeddings, in batches."""
    return np.concatenate([ev.embed_text(captions[i:i + batch]) for i in range(0, len(captions), batch)])
