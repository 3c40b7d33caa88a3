"""Options of the retargeting (:class:`RetargetConfig`) and its result (:class:`Reference`)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

HML_FPS: float = 20.0
CONTROL_HZ: float = 30.0


@dataclass(frozen=True)
class RetargetConfig:
    """Options of :func:`make_reference`.

    Attributes:
        fps: frame rate of the input joints (HumanML3D: 20).
        control_hz: rate of the produced reference (the tracker's rate, 30).
        ik_polish_iters: Gauss-Newton iterations polishing the closed-form IK (pass 1).
        ik_iters: Gauss-Newton iterations of the stance pass (pass 2), from pass 1.
        ik_damping: Levenberg damping (m²).
        posture_weight: pull of the hinges toward 0 (the upright rest pose).
        contact_height: a foot box is in contact below this sole height (m).
        contact_speed: ... and below this horizontal speed (m/s).
        smooth_sigma: Gaussian filter σ in input frames (0 = off).
        stance_pass: run the second, stance-holding IK pass.
        friction: friction coefficient of the pyramid in the ID screen.
        support_accel: infer support where the schedule has none: at frames whose COM
            vertical acceleration is above ``-support_accel·g`` (the body is not falling
            freely, so something holds it up) the lowest foot box is put in contact and
            pulled to the floor by the stance pass (0 = off). It recovers the toe push of a
            jump's take-off and the relevé of a dancer whose retargeted foot floats.
        support_reach: ... if that box's sole is within this height (m) of the floor.
        contact_spread: ridge weight that spreads the ID screen's contact forces over all
            touching corners (see :func:`inverse_dynamics_screen`; 0: plain NNLS).
        spike_distance: isolated joint samples this far (m) from their neighbours are
            mocap glitches and get replaced (0 = off).
        anchor_stance: move the whole body horizontally so that feet in contact stay where
            they touched down (:func:`~simdiff.sim.retarget.contacts.stance_anchor_shift`):
            a skating foot then carries no body translation the floor could not give. Off for
            the augmentation (mocap feet barely slide); on for the simulated finish of generated
            motion, whose stance feet drift with the body (measured: a generated jump in place
            slid 2.1 mm/frame after tracking without it, 0.06 with it). Where no foot is slow
            enough to count as planted but one is on the floor (a generated run gliding at
            2 m/s), the lowest foot box anchors the body
            (:func:`~simdiff.sim.retarget.contacts.skating_support`).
        swing_clearance: a foot box off contact moving faster than ``2·contact_speed`` must clear
            the floor by this much (m; ramped from 0 at ``contact_speed``); the stance pass lifts
            its foot (:func:`~simdiff.sim.retarget.contacts.swing_lift`). 0 = off (the
            augmentation: mocap swing feet clear the floor); on for the simulated finish, whose
            generated swing toes scrape the floor.
    """

    fps: float = HML_FPS
    control_hz: float = CONTROL_HZ
    ik_polish_iters: int = 3
    ik_iters: int = 4
    ik_damping: float = 1e-4
    posture_weight: float = 2e-3
    contact_height: float = 0.04
    contact_speed: float = 0.6
    smooth_sigma: float = 1.0
    stance_pass: bool = True
    friction: float = 0.8
    contact_spread: float = 1e-3
    support_accel: float = 0.5
    support_reach: float = 0.15
    spike_distance: float = 0.25
    anchor_stance: bool = False
    swing_clearance: float = 0.0


FINISH_SWING_CLEARANCE: float = 0.02
"""``RetargetConfig.swing_clearance`` (m) of the simulated finish. Measured on 48 generated samples
(the 4 bench prompts × g −9.81/−3.7 × seeds 0–5, shipped default model, probe not shipped; tracker
lead 1.5, not :data:`simdiff.sim.tracker.FINISH_LEAD`): rollouts
tracked to the end 33 → 41 (walks 3 → 10 of 12, runs 6 → 7, jumps 24 both); on the 24 walks and
runs 0.01 m tracked 15, 0.02 m 17, 0.03 m 16 (none: 9). Sliding is not reduced: ≤ 0.5 mm/frame
33 → 30 of 48, the walks tracked to the end with it slide 1.5 mm/frame on average (1.3 for the 3 tracked without it)."""


def finish_retarget(anchor_stance: bool = True) -> RetargetConfig:
    """The simulated finish's retargeting (planted feet anchored, swing feet lifted clear); with
    ``anchor_stance=False`` the plain one of the augmentation and PhysDiff."""
    if not anchor_stance:
        return RetargetConfig()
    return RetargetConfig(anchor_stance=True, swing_clearance=FINISH_SWING_CLEARANCE)


@dataclass
class Reference:
    """A retargeted reference at the control rate (K frames, dt = 1/control_hz).

    Attributes:
        qpos: (K, nq) joint positions (root pos m, root quat wxyz, 69 hinges rad).
        qvel: (K, nv); qacc: (K, nv).
        contact: (K, 4) bool reference contact of (L heel box, L toe, R heel box, R toe).
        com: (K, 3) whole-body COM (m, world); com_vel: (K, 3) m/s.
        body_pos: (K, 22, 3) world positions of the HumanML3D joints after retargeting.
        tau_ff: (K, 69) inverse-dynamics joint torques with reference contacts (N·m).
        root_residual: (K, 6) root wrench the contacts cannot supply (force N, torque N·m).
        dt: control period (s); n_in: input frame count; fps_in: input rate.
        ground_shift: metres added to the height to put the stance feet on the floor.
        ik_error: (T,) mean IK joint error per input frame (m).
    """

    qpos: np.ndarray
    qvel: np.ndarray
    qacc: np.ndarray
    contact: np.ndarray
    com: np.ndarray
    com_vel: np.ndarray
    body_pos: np.ndarray
    tau_ff: np.ndarray
    root_residual: np.ndarray
    dt: float
    n_in: int
    fps_in: float
    ground_shift: float = 0.0
    ik_error: np.ndarray = field(default_factory=lambda: np.zeros(0))

    @property
    def num_frames(self) -> int:
        return int(self.qpos.shape[0])

    @property
    def duration(self) -> float:
        """Length in seconds (first to last frame)."""
        return (self.n_in - 1) / self.fps_in

    def feasibility(self, mass: float, gravity: float = 9.81) -> dict[str, float]:
        """Summary of the ID screen: root residual force / (m g) and torque (N·m)."""
        f = np.linalg.norm(self.root_residual[:, :3], axis=1) / (mass * abs(gravity))
        t = np.linalg.norm(self.root_residual[:, 3:], axis=1)
        return {
            "force_median_mg": float(np.median(f)),
            "force_p90_mg": float(np.percentile(f, 90)),
            "frac_over_0.2mg": float(np.mean(f > 0.2)),
            "torque_median_nm": float(np.median(t)),
        }
