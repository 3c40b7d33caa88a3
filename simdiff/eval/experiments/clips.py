"""Real clips of the experiment's split, picked by motion type (the editing report's inputs, the readout check's)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from simdiff.errors import SimdiffError
from simdiff.eval.experiments.runner import Runner


def split_clips(runner: Runner, kind: str, n: int, min_frames: int = 0, flight: bool = False) -> list[dict[str, Any]]:
    """The first ``n`` original clips of motion type ``kind`` in the split (with ≥ ``min_frames`` frames, and a
    readable flight when ``flight``): ``{"id", "caption", "joints"}``, joints (T, 22, 3) float64 metres.

    Raises:
        SimdiffError: the split has none."""
    from simdiff.motion.gravity_readout import read_gravity

    corpus = Path(runner.config.corpus).expanduser()
    manifest = json.loads((corpus / "manifest.json").read_text(encoding="utf-8"))
    out = []
    for c in manifest["clips"]:
        if c.get("motion_type") != kind or c.get("mirror_of") or c.get("split") != runner.config.split:
            continue
        joints = np.load(corpus / "new_joints" / f"{c['id']}.npy", allow_pickle=False).astype(np.float64)
        if len(joints) < min_frames or (flight and read_gravity(joints) is None):
            continue
        out.append({"id": c["id"], "caption": (c.get("captions") or [""])[0], "joints": joints})
        if len(out) == n:
            break
    if not out:
        raise SimdiffError(f"the {runner.config.split} split has no clips of motion type {kind!r}"
                           + (" with a readable flight" if flight else ""))
    return out
