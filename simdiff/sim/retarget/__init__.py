"""HumanML3D joints ⇄ humanoid states, and the reference a tracker follows.

Modules: ``config`` (:class:`RetargetConfig`, :class:`Reference`), ``ik`` (closed-form IK
and its Gauss-Newton polish), ``kinematics`` (forward kinematics: joints, foot soles, COM),
``contacts`` (contact schedule, inferred support, floor level, stance tasks), ``filtering``
(despiking, smoothing, resampling, velocities), ``dynamics`` (the inverse-dynamics screen),
``reference`` (:func:`make_reference`, the whole forward conversion). MuJoCo is imported lazily.
"""

from simdiff.sim.retarget.config import CONTROL_HZ, HML_FPS, Reference, RetargetConfig, finish_retarget
from simdiff.sim.retarget.ik import analytic_ik, ik_sequence
from simdiff.sim.retarget.kinematics import foot_heights, joints_to_features, qpos_to_joints, qpos_to_world
from simdiff.sim.retarget.reference import make_reference

__all__ = [
    "CONTROL_HZ", "HML_FPS", "Reference", "RetargetConfig", "analytic_ik", "finish_retarget", "foot_heights", "ik_sequence",
    "joints_to_features", "make_reference", "qpos_to_joints", "qpos_to_world",
]
