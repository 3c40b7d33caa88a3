"""A cheaper denoiser design: the same transformer on a lower frame rate, upsampled to 20 fps.

A ``factor``-times lower frame rate shortens every sequence ``factor`` times, so a training
step costs about ``factor``× less attention and feed-forward work at the same seconds of motion.
The low-rate corpus is made by recovering each clip's joints (``features_to_joints``), keeping
every ``factor``-th frame and running HumanML3D's processing again (``process_joints``, foot-
contact threshold scaled by ``factor²`` so it stays the same speed, ≈ 0.89 m/s). Samples go
back to 20 fps by linear interpolation of the joints and the same processing.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from simdiff.errors import SimdiffError
from simdiff.fsio import save_npy, write_json, write_text
from simdiff.motion.features import FEET_THRESHOLD, extend_last_frame, features_to_joints, process_joints
from simdiff.motion.normalize import Normalizer

SETTINGS_NAME = "lowfps.json"


def clip_joints(features: np.ndarray) -> np.ndarray:
    """(T, 263) raw features → (T+1, 22, 3) joints (the frame after the last row rebuilt from its velocities)."""
    f = np.asarray(features, dtype=np.float32)
    return extend_last_frame(np.asarray(features_to_joints(f), dtype=np.float32), f)


def downsample_features(features: np.ndarray, factor: int) -> np.ndarray:
    """(T, 263) features at 20 fps → (⌈(T+1)/factor⌉ − 1, 263) features at 20/factor fps."""
    joints = clip_joints(features)[::factor]
    if len(joints) < 2:
        raise SimdiffError(f"a {len(features)}-frame clip is too short for frame-rate factor {factor}")
    return process_joints(joints, feet_threshold=FEET_THRESHOLD * factor**2).features


def upsample_joints(joints: np.ndarray, factor: int) -> np.ndarray:
    """(T, 22, 3) joints → ((T−1)·factor + 1, 22, 3) by linear interpolation in time."""
    j = np.asarray(joints, dtype=np.float32)
    t = np.arange((len(j) - 1) * factor + 1, dtype=np.float64) / factor
    lo = np.minimum(np.floor(t).astype(int), len(j) - 1)
    hi = np.minimum(lo + 1, len(j) - 1)
    w = (t - lo)[:, None, None].astype(np.float32)
    return (1.0 - w) * j[lo] + w * j[hi]


def upsample_features(features: np.ndarray, factor: int) -> np.ndarray:
    """(L, 263) low-rate features → (L·factor, 263) features at 20 fps."""
    return process_joints(upsample_joints(clip_joints(features), factor)).features


def _whole_captions(text: str) -> str:
    """Caption lines with their segment times dropped (times are in 20 fps seconds; clips are windows)."""
    lines = []
    for line in text.splitlines():
        parts = line.split("#")
        if len(parts) >= 4:
            parts[2] = parts[3] = "0.0"
        lines.append("#".join(parts))
    return "\n".join(lines) + "\n"


def build_lowfps_corpus(src: str | Path, out: str | Path, factor: int = 2, progress: bool = True) -> int:
    """Write the ``factor``-times lower frame-rate copy of corpus ``src`` to ``out``; returns the clip count.

    Resumable: clips already written are kept (the settings file must match). Mean/Std are
    fitted on the new train split; split files list the clips that were written.
    """
    from tqdm import tqdm

    src, out = Path(src), Path(out)
    if factor < 2:
        raise SimdiffError(f"frame-rate factor must be >= 2, got {factor}")
    settings = {"source": str(src.resolve()), "factor": factor}
    marker = out / SETTINGS_NAME
    if marker.is_file():
        import json

        if json.loads(marker.read_text()) != settings:
            raise SimdiffError(f"{out} holds a low-frame-rate corpus of other settings; use a new folder")
    splits = {p.stem: p.read_text().split() for p in sorted(src.glob("*.txt"))}
    if not splits.get("train"):
        raise SimdiffError(f"{src}: no train.txt (not a HumanML3D-layout corpus)")
    write_json(marker, settings)
    ids = sorted({i for members in splits.values() for i in members})
    written: set[str] = set()
    for clip in tqdm(ids, desc=f"{20 // factor} fps corpus", disable=not progress, dynamic_ncols=True):
        target = out / "new_joint_vecs" / f"{clip}.npy"
        text = src / "texts" / f"{clip}.txt"
        if not target.is_file():
            feats_path = src / "new_joint_vecs" / f"{clip}.npy"
            if not feats_path.is_file() or not text.is_file():
                continue
            feats = np.load(feats_path).astype(np.float32)
            if (len(feats) + 1) // factor < 2:
                continue
            low = downsample_features(feats, factor)
            save_npy(out / "new_joints" / f"{clip}.npy", np.asarray(features_to_joints(low), dtype=np.float32))
            write_text(out / "texts" / f"{clip}.txt", _whole_captions(text.read_text(encoding="utf-8")))
            save_npy(target, low)
        written.add(clip)
    for name, members in splits.items():
        write_text(out / f"{name}.txt", "".join(f"{m}\n" for m in members if m in written))
    train = [np.load(out / "new_joint_vecs" / f"{m}.npy") for m in splits["train"] if m in written]
    Normalizer.fit(train).save(out)
    return len(written)
