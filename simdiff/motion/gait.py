"""Gait measures of a motion: how fast it travels, how much its limbs move, its step rate and ground time.

Joints (T, 22, 3) metres, Y up, HumanML3D order, ``fps`` frames per second (20). A foot is on the ground when its
ankle or its toe is within :data:`simdiff.motion.flight.LIFT` (5 cm) of that joint's own ground level (the rule of
:mod:`simdiff.motion.flight`); a step is a foot coming down (off → on), after the first frame.

* pelvis_speed (m/s): horizontal pelvis path length over the duration;
* limb_speed (m/s): mean speed of the wrists and ankles relative to the pelvis (a frozen pose carried along the
  floor has pelvis speed but no limb speed);
* cadence (steps/min): foot strikes of both feet per minute;
* duty_factor: share of frames each foot is on the ground, averaged over the two feet (walks > 0.5, runs < 0.5).
"""

from __future__ import annotations

import numpy as np

from simdiff.motion.flight import FEET, LIFT, check_joints, heights_over_ground, runs
from simdiff.motion.skeleton import FPS

LIMBS: tuple[int, int, int, int] = (7, 8, 20, 21)
"""Left and right ankle, left and right wrist."""


def foot_contacts(joints: np.ndarray) -> np.ndarray:
    """(T, 2) bool: the left and right foot on the ground (ankle or toe within 5 cm of its own ground level)."""
    low = heights_over_ground(joints) <= LIFT  # (T, 4), columns in FEET order
    left = [FEET.index(7), FEET.index(10)]
    right = [FEET.index(8), FEET.index(11)]
    return np.stack([low[:, left].any(axis=1), low[:, right].any(axis=1)], axis=1)


def gait_measures(joints: np.ndarray, fps: float = FPS) -> dict[str, float]:
    """The measures of the module docstring for one motion (T ≥ 2)."""
    j = check_joints(joints)
    seconds = (len(j) - 1) / fps
    pelvis = np.linalg.norm(np.diff(j[:, 0, [0, 2]], axis=0), axis=-1).sum() / seconds
    relative = j[:, list(LIMBS)] - j[:, :1]
    limbs = float(np.linalg.norm(np.diff(relative, axis=0), axis=-1).mean() * fps)
    contact = foot_contacts(j)
    strikes = sum(1 for side in range(2) for start, _ in runs(contact[:, side]) if start > 0)
    return {"pelvis_speed": float(pelvis), "limb_speed": limbs, "cadence": 60.0 * strikes / seconds,
            "duty_factor": float(contact.mean())}
