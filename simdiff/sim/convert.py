"""Compatibility shim: the conversion now lives in :mod:`simdiff.sim.retarget`."""

from simdiff.sim.retarget import (  # noqa: F401
    CONTROL_HZ, HML_FPS, Reference, RetargetConfig, foot_heights, ik_sequence, joints_to_features,
    make_reference, qpos_to_joints, qpos_to_world,
)
