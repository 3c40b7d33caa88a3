"""Contact schedule, inferred support, floor level and the stance-holding IK tasks.

Heights in metres (world Z-up), speeds in m/s, schedules (T, 4) bool per foot box
(L heel box, L toe, R heel box, R toe) at the input rate.
"""

from __future__ import annotations

import numpy as np
from scipy.ndimage import distance_transform_edt, gaussian_filter1d, maximum_filter1d
from scipy.spatial.transform import Rotation

from simdiff.motion.flight import runs
from simdiff.sim.retarget.config import RetargetConfig
from simdiff.sim.retarget.ik import IKTask
from simdiff.sim.retarget.kinematics import box_bottom_corners, foot_geoms


ANCHOR_VERSION: int = 7
"""Version of the simulated finish's retargeting rules (``RetargetConfig.anchor_stance`` and
``swing_clearance``), recorded with simulated finishes and in the experiments' row inputs: 1 planted
feet only, 2 also the lowest foot where every foot on the floor glides (:func:`skating_support`),
3 also swing feet lifted clear of the floor (:func:`swing_lift`, :data:`~simdiff.sim.retarget.config.FINISH_SWING_CLEARANCE`),
4 also the tracker's longer lead (:data:`simdiff.sim.tracker.FINISH_LEAD`), 5 also no horizontal
position term in the tracker's balance layer while the reference moves (:data:`simdiff.sim.tracker.FINISH_MOVING_KP_XY`),
6 also a swing foot that lands after the reference's keeps its placement (:data:`simdiff.sim.tracker.FINISH_LATE_FOOT`),
7 also a second try under the slip guard when the rollout fell or slid (:func:`simdiff.sim.fallback.finish_fallback`)."""


def _box_speed(xy: np.ndarray, fps: float) -> np.ndarray:
    """(T, 4) horizontal speed (m/s) of the foot boxes from their centres (T, 4, 2)."""
    return np.linalg.norm(np.gradient(xy, axis=0) * fps, axis=-1)


def contact_schedule(height: np.ndarray, xy: np.ndarray, fps: float, cfg: RetargetConfig) -> np.ndarray:
    """(T, 4) bool: a foot box touches when low (< contact_height) and slow (< contact_speed)."""
    speed = _box_speed(xy, fps)
    c = (height < cfg.contact_height) & (speed < cfg.contact_speed)
    # a one-frame gap or blip is noise
    for k in range(4):
        col = c[:, k]
        for t in range(1, len(col) - 1):
            if col[t - 1] == col[t + 1] != col[t]:
                col[t] = col[t - 1]
    return c


def skating_support(contact: np.ndarray, height: np.ndarray, reach: float, tol: float = 0.01) -> np.ndarray:
    """(T, 4) bool: the lowest foot boxes at frames where none is in contact but one is on the floor.

    A generated motion whose stance foot glides (a "run" that skates at 2 m/s) has low feet that
    are never slow enough for :func:`contact_schedule`; physically the lowest one is the support.
    At frames without a scheduled contact whose lowest sole is below ``reach`` (m), every box
    within ``tol`` (m) of the lowest is marked (a flat foot's heel and toe boxes, which a strict
    argmin would alternate between); frames above ``reach`` are flight and get none.

    Args:
        contact: (T, 4) bool schedule; height: (T, 4) sole heights above the floor (m).
    """
    contact = np.asarray(contact, dtype=bool)
    low = height.min(axis=1, keepdims=True)
    free = ~contact.any(axis=1, keepdims=True) & (low < reach)
    return free & (height <= low + tol)


def swing_lift(contact: np.ndarray, height: np.ndarray, xy: np.ndarray, fps: float, clearance: float,
               speed_lo: float, speed_hi: float, taper: float = 3.0) -> np.ndarray:
    """(T, 2) upward lift (m) of the left and right foot that gives fast swing feet ``clearance``.

    A generated walk's swing toe often passes at or below its stance foot's level (measured: the
    bench walk's reference scraped the floor at 5 m/s, 12 mm under it, and the tracked toe caught
    and slid). A foot box off contact that moves faster than ``speed_lo`` (m/s) must clear the
    floor by ``clearance`` (m) scaled by a ramp reaching 1 at ``speed_hi``; a slow box (landing,
    lift-off) needs none. The foot's lift is the larger deficit of its two boxes, widened by one
    frame on each side and smoothed (σ = 1 frame), then tapered to 0 over ``taper`` frames towards
    any frame where a box of that foot is in contact (none there): the lift never jumps at a
    touch-down or a lift-off, and a landing foot may come down.

    Args:
        contact: (T, 4) bool (L heel box, L toe, R heel box, R toe); height: (T, 4) sole heights
            above the floor (m); xy: (T, 4, 2) box centres (m); fps: frame rate.
    """
    contact = np.asarray(contact, dtype=bool)
    T = contact.shape[0]
    if clearance <= 0 or T == 0:
        return np.zeros((T, 2))
    speed = _box_speed(xy, fps)
    ramp = np.clip((speed - speed_lo) / max(speed_hi - speed_lo, 1e-9), 0.0, 1.0)
    need = np.where(contact, 0.0, np.maximum(0.0, clearance * ramp - height)).reshape(T, 2, 2).max(axis=2)
    wide = maximum_filter1d(need, 3, axis=0, mode="constant")
    lift = gaussian_filter1d(wide, 1.0, axis=0, mode="constant", truncate=3.0)
    planted = contact.reshape(T, 2, 2).any(axis=2)
    return lift * np.clip(_frames_to(planted) / taper, 0.0, 1.0)


def _frames_to(mask: np.ndarray) -> np.ndarray:
    """(T, F) frames from each frame to the nearest True of its column of ``mask`` (T, F) (T when none)."""
    dist = np.full(mask.shape, float(mask.shape[0]))
    for f in range(mask.shape[1]):
        if mask[:, f].any():
            dist[:, f] = distance_transform_edt(~mask[:, f])  # 1-D: |frame − nearest True|
    return dist


def stance_anchor_shift(contact: np.ndarray, xy: np.ndarray) -> np.ndarray:
    """(T, 2) horizontal offset (m) that keeps feet in contact where they touched down.

    Between frames t and t+1 the body is moved back by the mean horizontal displacement of the
    foot boxes in contact at both frames; the moves accumulate (the offset at frame 0 is 0). A
    motion whose planted feet slide with the body (a generated "jump in place" that drifts on the
    spot) loses that drift; a walk keeps the travel its steps make and loses the skating part.

    Args:
        contact: (T, 4) bool schedule (:func:`contact_schedule`); xy: (T, 4, 2) box centres (m).
    """
    contact = np.asarray(contact, dtype=bool)
    step = np.diff(np.asarray(xy, dtype=np.float64), axis=0)  # (T-1, 4, 2)
    held = contact[:-1] & contact[1:]  # (T-1, 4)
    n = held.sum(axis=1, keepdims=True)
    mean = (step * held[..., None]).sum(axis=1) / np.maximum(n, 1)
    return np.concatenate([np.zeros((1, 2)), -np.cumsum(mean, axis=0)])


_D2_QUADRATIC5: np.ndarray = np.array([2.0, -1.0, -2.0, -1.0, 2.0]) / 7.0
"""Least-squares quadratic over 5 equally spaced samples: its (constant) second derivative, per unit step²."""


def second_derivative5(x: np.ndarray, fps: float) -> np.ndarray:
    """(T,) → (T,) second derivative (units/s²) of quadratic least-squares fits over 5 frames (T ≥ 5).

    Exact for free fall. The same as ``scipy.signal.savgol_filter(x, 5, 2, deriv=2, delta=1/fps,
    mode="interp")`` (the two frames at each end take the fit of the first / last window), without
    importing ``scipy.signal`` (about 0.5 s, a quarter of a simulated finish's budget).
    """
    x = np.asarray(x, dtype=np.float64)
    mid = np.correlate(x, _D2_QUADRATIC5, mode="valid") * fps * fps  # (T-4,) at frames 2 .. T-3
    return np.concatenate([np.full(2, mid[0]), mid, np.full(2, mid[-1])])


def infer_support(contact: np.ndarray, height: np.ndarray, xy: np.ndarray, com_z: np.ndarray, fps: float,
                  accel: float, reach: float, max_speed: float = 0.6, gravity: float = 9.81) -> np.ndarray:
    """(T, 4) bool: foot boxes that must carry the body although the schedule has none down.

    A frame is *supported* when the smoothed COM vertical acceleration exceeds
    ``-accel·gravity`` (m/s²): a body in free fall accelerates at -g, so anything clearly
    above that needs a floor force. At supported frames without any scheduled contact, the
    lowest box is added if its sole is below ``reach`` (m) and it moves slower than
    ``max_speed`` (m/s, horizontal; a sliding foot is not a support). Contacts are only
    added, never removed.

    Args:
        contact: (T, 4) schedule from heights; height: (T, 4) sole heights (m);
        xy: (T, 4, 2) box centres (m); com_z: (T,) COM height (m); fps: frame rate.
    """
    if accel <= 0 or len(com_z) < 5:
        return np.zeros_like(contact)
    az = second_derivative5(com_z, fps)
    need = (az > -accel * gravity) & ~contact.any(axis=1)
    low = height.argmin(axis=1)
    idx = np.arange(len(low))
    speed = _box_speed(xy, fps)[idx, low]
    out = np.zeros_like(contact)
    rows = np.flatnonzero(need & (height[idx, low] < reach) & (speed < max_speed))
    out[rows, low[rows]] = True
    return out


def ground_level(height: np.ndarray, xy: np.ndarray, fps: float, still_speed: float = 0.3) -> float:
    """Floor height (m) of a motion from its foot-box sole heights (T, 4) and centres (T, 4, 2).

    The median sole height of the lowest box over the frames where that box is still
    (horizontal speed below ``still_speed``): a planted foot is on the floor, whatever the
    capture's own zero. Falls back to the 10th percentile of the lowest sole when fewer than
    5 frames are still (a motion that never plants a foot).
    """
    low_box = height.argmin(axis=1)
    low = height[np.arange(len(height)), low_box]
    speed = _box_speed(xy, fps)[np.arange(len(height)), low_box]
    still = speed < still_speed
    if still.sum() >= 5:
        return float(np.median(low[still]))
    return float(np.percentile(low, 10))


def stance_tasks(model, qpos: np.ndarray, contact: np.ndarray, weight: float = 20.0,
                  max_tilt: float = np.deg2rad(12.0), reach: np.ndarray | None = None,
                  lift: np.ndarray | None = None) -> list[list[IKTask]]:
    """Per-frame tasks that hold each touching foot box flat, on the floor, at a fixed xy.

    Only frames where the box is nearly flat already (tilt below ``max_tilt``) are held: a
    heel rising at toe-off or a toe coming down at heel strike keeps its own pitch (forcing
    it flat would pull the whole body out of shape). The hold's weight ramps over the first
    and last 2 frames of an interval. Boxes marked in ``reach`` (T, 4) (inferred support, see
    :func:`infer_support`) get a position task that lowers them, tilt kept, until their lowest
    corner touches the floor. ``lift`` (T, 2) (:func:`swing_lift`) raises both boxes of the left
    and right foot by that many metres where positive, their tilt kept.
    """
    import mujoco

    d = mujoco.MjData(model)
    names = ("L_Ankle", "L_Toe", "R_Ankle", "R_Toe")
    bodies = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, n) for n in names]
    # flat-pose height of each body origin above the floor
    d.qpos[:] = model.qpos0
    mujoco.mj_kinematics(model, d)
    geoms = foot_geoms(model)
    rest_h = [d.xpos[b][2] - box_bottom_corners(model, d, g)[:, 2].min() for b, g in zip(bodies, geoms)]
    pos = np.zeros((qpos.shape[0], 4, 3))
    yaw = np.zeros((qpos.shape[0], 4))
    flat = np.zeros((qpos.shape[0], 4), dtype=bool)
    for t in range(qpos.shape[0]):
        d.qpos[:] = qpos[t]
        mujoco.mj_kinematics(model, d)
        for k, b in enumerate(bodies):
            pos[t, k] = d.xpos[b]
            R = d.xmat[b].reshape(3, 3)
            yaw[t, k] = np.arctan2(R[1, 0], R[0, 0])
            flat[t, k] = R[2, 2] > np.cos(max_tilt)
    tasks: list[list[IKTask]] = [[] for _ in range(qpos.shape[0])]
    for k, b in enumerate(bodies):
        for s, e in runs(contact[:, k] & flat[:, k]):
            p = np.median(pos[s:e, k], axis=0)
            p[2] = rest_h[k]
            y = float(np.angle(np.mean(np.exp(1j * yaw[s:e, k]))))
            R = Rotation.from_euler("z", y).as_matrix()
            for t in range(s, e):  # ramp in and out over 2 frames: no jump when a hold starts
                ramp = min(1.0, (t - s + 1) / 2, (e - t) / 2)
                tasks[t].append(IKTask(b, p, R, weight * ramp))
    if reach is not None:
        for k, (b, g) in enumerate(zip(bodies, geoms)):
            for t in np.flatnonzero(reach[:, k]):
                d.qpos[:] = qpos[t]
                mujoco.mj_kinematics(model, d)
                drop = box_bottom_corners(model, d, g)[:, 2].min()
                tasks[t].append(IKTask(b, d.xpos[b] - np.array([0.0, 0.0, drop]), None, weight))
    if lift is not None:
        for k, b in enumerate(bodies):
            for t in np.flatnonzero(lift[:, k // 2] > 1e-4):
                tasks[t].append(IKTask(b, pos[t, k] + np.array([0.0, 0.0, lift[t, k // 2]]), None, weight))
    return tasks
