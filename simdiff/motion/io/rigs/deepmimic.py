"""DeepMimic humanoid3d (JSON motions): map and the ground clean-up applied after retargeting."""

from __future__ import annotations

from simdiff.motion.io.ground import lift_penetrations
from simdiff.motion.io.rigs.base import RigSpec, Source

DEEPMIMIC_MAP: dict[str, Source] = {
    "pelvis": "root",
    "left_hip": "left_hip",
    "right_hip": "right_hip",
    "spine1": ("root", "chest", 0.5),
    "left_knee": "left_knee",
    "right_knee": "right_knee",
    "spine2": "chest",
    "left_ankle": "left_ankle",
    "right_ankle": "right_ankle",
    "spine3": ("chest", "neck", 0.25),
    "left_foot": "left_toe",
    "right_foot": "right_toe",
    "neck": "neck_top",
    "left_collar": ("neck", "left_shoulder", 0.45),
    "right_collar": ("neck", "right_shoulder", 0.45),
    "head": "head",
    "left_shoulder": "left_shoulder",
    "right_shoulder": "right_shoulder",
    "left_elbow": "left_elbow",
    "right_elbow": "right_elbow",
    "left_wrist": "left_wrist",
    "right_wrist": "right_wrist",
}
"""DeepMimic humanoid3d links and derived sites -> HumanML3D joints."""

DEEPMIMIC: RigSpec = RigSpec("deepmimic", DEEPMIMIC_MAP, finish=lift_penetrations)
"""Retargeted DeepMimic clips get :func:`simdiff.motion.io.ground.lift_penetrations`."""
