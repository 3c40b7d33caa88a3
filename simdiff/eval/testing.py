"""A tiny synthetic corpus in the HumanML3D layout, for tests and smoke runs of the eval tools.

Clips are procedural walks (speed, turn, stride vary) and jumps from
:mod:`simdiff.motion.synthetic`, processed like a real corpus (``process_joints``); each
has a caption that names what varies, so a text–motion evaluator has something to learn.
Not data.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from simdiff.motion.features import features_to_joints, process_joints
from simdiff.motion.normalize import Normalizer
from simdiff.motion.synthetic import jump, walk


def _clip(i: int, rng: np.random.Generator, frames: int) -> tuple[np.ndarray, str]:
    kind = i % 3
    if kind == 2:
        height = float(rng.uniform(0.2, 0.5))
        return jump(frames, height=height, start=frames // 3), f"a person jumps {'high' if height > 0.35 else 'low'}"
    speed = float(rng.uniform(0.6, 1.8))
    turn = float(rng.choice([-0.8, 0.0, 0.8]))
    pace = "fast" if speed > 1.2 else "slowly"
    where = {-0.8: "turning right", 0.0: "straight ahead", 0.8: "turning left"}[turn]
    return walk(frames, speed=speed, turn_rate=turn, phase=float(rng.uniform(0, 6.28))), f"a person walks {pace} {where}"


def write_tiny_corpus(root: str | Path, n_train: int = 12, n_test: int = 6, frames: int = 64, seed: int = 0,
                      n_val: int = 0) -> Path:
    """Write ``n_train + n_val + n_test`` clips of ``frames`` joint frames to ``root``; returns ``root``.

    Files: ``new_joint_vecs`` (frames-1, 263), ``new_joints`` (frames-1, 22, 3), ``texts``,
    ``Mean.npy``/``Std.npy`` (grouped HumanML3D statistics of all clips), split files.
    """
    root = Path(root)
    for sub in ("new_joint_vecs", "new_joints", "texts"):
        (root / sub).mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(seed)
    ids, feats = [], []
    for i in range(n_train + n_val + n_test):
        joints, caption = _clip(i, rng, frames)
        f = process_joints(joints).features
        clip_id = f"{i:06d}"
        np.save(root / "new_joint_vecs" / f"{clip_id}.npy", f)
        np.save(root / "new_joints" / f"{clip_id}.npy", np.asarray(features_to_joints(f), dtype=np.float32))
        tokens = " ".join(f"{w}/OTHER" for w in caption.split())
        (root / "texts" / f"{clip_id}.txt").write_text(f"{caption}#{tokens}#0.0#0.0\n", encoding="utf-8")
        ids.append(clip_id)
        feats.append(f)
    Normalizer.fit(feats).save(root)
    splits = {"train": ids[:n_train], "val": ids[n_train : n_train + n_val], "test": ids[n_train + n_val :]}
    for name, members in splits.items():
        (root / f"{name}.txt").write_text("".join(f"{m}\n" for m in members), encoding="utf-8")
    (root / "all.txt").write_text("".join(f"{m}\n" for m in ids), encoding="utf-8")
    return root
