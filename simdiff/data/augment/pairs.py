"""One augmented pair on disk: its id, the source clip's joints it was simulated from, and the files and shard
record written for it. Shared by a run (:mod:`.run`) and the re-simulation of stale pairs (:mod:`.resim`)."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

import numpy as np

from simdiff.data.augment.conditions import AugmentEnv
from simdiff.data.writer import write_bytes, write_npy
from simdiff.errors import SimdiffError
from simdiff.sim.project import SIM_VERSION


def clip_id_for(clip: str, condition: AugmentEnv) -> str:
    """Id of the augmented copy of ``clip`` under ``condition``."""
    return f"{clip}_e{condition.index:02d}"


def load_source_joints(corpus: Path, clip: str) -> np.ndarray:
    """The full (T, 22, 3) joint sequence of a source clip (T = feature rows + 1).

    Uses ``new_joints`` (T-1 frames, as HumanML3D ships them) extended by the last feature
    row's velocities; falls back to recovering the joints from the features.
    """
    from simdiff.motion.features import extend_last_frame, features_to_joints

    feats_path = corpus / "new_joint_vecs" / f"{clip}.npy"
    if not feats_path.is_file():
        raise SimdiffError(f"{feats_path}: missing features of clip {clip}")
    feats = np.load(feats_path, allow_pickle=False).astype(np.float32)
    joints_path = corpus / "new_joints" / f"{clip}.npy"
    joints = np.load(joints_path, allow_pickle=False) if joints_path.is_file() else features_to_joints(feats)
    joints = np.asarray(joints, dtype=np.float32)
    if joints.shape != (len(feats), 22, 3):
        joints = np.asarray(features_to_joints(feats), dtype=np.float32)
    return extend_last_frame(joints, feats)


def rollout_to_layout(rollout: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(T, 22, 3) rollout joints → ((T-1, 263) features, (T-1, 22, 3) joints) as the corpus stores them."""
    from simdiff.motion.features import features_to_joints, process_joints

    features = process_joints(np.asarray(rollout, dtype=np.float64)).features.astype(np.float32)
    if not np.all(np.isfinite(features)):
        raise SimdiffError("non-finite features from a rollout")
    return features, np.asarray(features_to_joints(features), dtype=np.float32)


def info_dict(info: Any) -> Any:
    """A projector's info as JSON-friendly data (None, an error string and dicts pass through)."""
    if info is None or isinstance(info, (str, dict)):
        return info
    to_dict = getattr(info, "to_dict", None)
    return to_dict() if callable(to_dict) else dataclasses.asdict(info)


def _tracked(info: Any) -> bool:
    return bool(getattr(info, "success", False) or (isinstance(info, dict) and info.get("success")))


def pair_record(corpus: Path, out: Path, clip: str, cond: AugmentEnv, rollout: np.ndarray | None, info: Any,
                 content: dict[str, float] | None) -> dict[str, Any]:
    """Write a tracked pair's files (features, joints, caption) and return its shard record.

    The record's ``written`` says whether the files exist; ``reason`` is ``"error"`` when the
    projection or the conversion failed (None otherwise; the keep decision is made at finalize).
    """
    from simdiff.data.augment.signal import measure

    aid = clip_id_for(clip, cond)
    written, reason = False, ("error" if info is None or isinstance(info, str) else None)
    if reason is None and rollout is not None and _tracked(info):
        try:
            feats, joints = rollout_to_layout(rollout)
        except SimdiffError as exc:
            reason, info = "error", str(exc)
        else:
            write_npy(out / "new_joint_vecs" / f"{aid}.npy", feats)
            write_npy(out / "new_joints" / f"{aid}.npy", joints)
            write_bytes(out / "texts" / f"{aid}.txt", (corpus / "texts" / f"{clip}.txt").read_bytes())
            written = True
    signal = None
    if written:
        try:
            signal = measure(rollout)
        except SimdiffError:
            signal = None
    return {"clip": clip, "condition": cond.index, "id": aid, "written": written, "reason": reason, "info": info,
            "env": list(cond.env.as_tuple()), "factor": cond.factor, "signal": signal, "content": content,
            "sim_version": SIM_VERSION}
