"""Kinematic detectors for prompt following: did a motion do what its words asked?

No learned evaluator: each detector reads joints (T, 22, 3), metres, Y up, HumanML3D order, 20 fps, and returns a
:class:`Verdict` with the measured value. A check is written ``"name:argument"`` (:func:`run_check`):

* ``direction:forward|backward|left|right``: the root's travel summed in the body's own frame (each frame's
  velocity taken along that frame's facing), so walking backward is not read as turning and walking forward;
  passes when that component is ≥ :data:`MIN_TRAVEL` and ≥ :data:`DOMINANT` of the travel.
* ``turn:left|right|around``: the largest facing change from the first frame (left = counter-clockwise seen from
  above); left/right ≥ :data:`TURN_DEG` that way, around ≥ :data:`AROUND_DEG` either way.
* ``travel:return|in_place|away``: return = goes ≥ :data:`RETURN_OUT` m from the start and ends within half of
  its farthest distance; in place = the root stays within :data:`IN_PLACE` m of the start; away = ends ≥ :data:`AWAY` m from it.
* ``circle:``: the facing keeps turning at circle pace, sweeping ≥ :data:`CIRCLE_RATE` °/s over the whole motion
  (≥ :data:`CIRCLE_MIN_DEG`), while the root walks a path ≥ :data:`CIRCLE_PATH` m.
* ``count:jumps=N``: exactly N jumps: flights (every foot up, :func:`simdiff.motion.flight.flights`) of at least
  :data:`JUMP_FRAMES` frames (a run's flight phases are shorter);
  ``count:squats=N``: exactly N dips of the pelvis below :data:`CROUCH` of its standing height.
* ``side:leg=left|right``: that ankle rises ≥ :data:`KICK_HEIGHT` m over the floor and ≥ :data:`SIDE_MARGIN` m
  higher than the other; ``side:arm=left|right``: that wrist rises to within :data:`SHOULDER_SLACK` of its
  shoulder and ≥ :data:`SIDE_MARGIN` m higher (relative to the pelvis) than the other.
* ``posture:sit_stand|lie_get_up|crouch|pick_up|sit``: pelvis and wrist heights against the standing pelvis
  height of the motion's own legs (:func:`standing_height`); sitting and lying are held ≥ :data:`HOLD_FRAMES`.
* ``order:A<B``: event A starts before event B (events: travel, jump, sit, crouch, raise (a wrist over the head),
  turn (≥ :data:`TURN_DEG`), lie).
* ``speed:slower|faster`` needs a reference motion (the same seed without the speed word): pelvis speed ratio
  ≤ :data:`SLOWER` or ≥ :data:`FASTER`; both must travel ≥ :data:`MIN_TRAVEL` (a standstill is not a pace).

Heights alone cannot tell every posture apart: a deep squat held a second reads as sitting, sitting on the floor as
crouching, a seated reach to the floor as picking up. Thresholds were set on ground-truth train-split clips whose
captions name the action; several checks (sidesteps, counts, speed, sequences, sit and lie transitions) have no such
clip (:mod:`simdiff.eval.experiments.following` reports each rule's pass rate on the test split's clips).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from simdiff.errors import SimdiffError
from simdiff.motion.flight import check_joints, flights, runs
from simdiff.motion.kinematics import facing_direction
from simdiff.motion.skeleton import FACE_JOINTS, FPS

MIN_TRAVEL: float = 0.5
"""m of travel a direction needs."""
DOMINANT: float = 0.6
"""Share of the travel (as a vector length) along the asked direction."""
TURN_DEG: float = 60.0
AROUND_DEG: float = 135.0
RETURN_OUT: float = 1.0
IN_PLACE: float = 0.6
AWAY: float = 1.0
CIRCLE_RATE: float = 35.0
"""°/s: a full circle in 10 s; the corpus's circle clips are 2 s arcs of 58–132° (median 100°)."""
CIRCLE_MIN_DEG: float = 70.0
CIRCLE_PATH: float = 1.5
CROUCH: float = 0.75
"""Pelvis below this share of its standing height: crouched (squat, sit, pick up)."""
SIT: float = 0.72
LIE: float = 0.35
"""m: pelvis below this is lying (or sitting on the floor)."""
HOLD_FRAMES: int = 10
"""Frames (0.5 s) a sitting or lying pelvis height is held; a squat's bottom is briefer."""
STOOD: float = 0.85
"""The last second's mean pelvis height above this share of standing: back up."""
PICK_WRIST: float = 0.35
"""m: a wrist this low reaches the floor."""
KICK_HEIGHT: float = 0.3
SIDE_MARGIN: float = 0.1
SHOULDER_SLACK: float = 0.1
"""m: a raised wrist reaches at least this close below its shoulder (gentle raises stop at shoulder height)."""
SLOWER: float = 0.8
FASTER: float = 1.25
JUMP_FRAMES: int = 6
"""A flight this long (0.3 s) is a jump: 103 of the train split's 120 jump-clip flights, 6 of its 1,053 run-clip
flights (running strides fly 2–5 frames)."""
EVENTS: tuple[str, ...] = ("travel", "jump", "sit", "crouch", "raise", "turn", "lie")

_LEFT = {"leg": 7, "arm": 20}
_RIGHT = {"leg": 8, "arm": 21}
_SHOULDER = {"left": 16, "right": 17}


@dataclass(frozen=True)
class Verdict:
    """A detector's answer: passed, the measured value and a short reading ("backward 1.32 m")."""

    passed: bool
    value: float
    reading: str


def floored(joints: np.ndarray) -> np.ndarray:
    """(T, 22, 3) float64 with the lowest foot joint's 5th-percentile height at y = 0."""
    j = check_joints(joints).copy()
    j[..., 1] -= np.percentile(j[:, [7, 8, 10, 11], 1].min(axis=1), 5.0)
    return j


def standing_height(joints: np.ndarray) -> float:
    """m: the pelvis height of this body standing straight (thigh + shin + 0.15 m of ankle and pelvis)."""
    j = check_joints(joints)
    leg = [np.linalg.norm(j[:, a] - j[:, b], axis=-1).mean() for a, b in ((1, 4), (4, 7), (2, 5), (5, 8))]
    return float((leg[0] + leg[1] + leg[2] + leg[3]) / 2.0 + 0.15)


def yaw(joints: np.ndarray) -> np.ndarray:
    """(T,) facing angle about +Y, unwrapped, degrees (0 = +Z; increasing = turning left); facing smoothed σ 2 frames."""
    forward = facing_direction(joints, FACE_JOINTS, smooth_sigma=2.0)
    return np.degrees(np.unwrap(np.arctan2(forward[:, 0], forward[:, 2])))


def body_travel(joints: np.ndarray) -> tuple[float, float]:
    """(forward, left) m: the root's horizontal steps summed along each frame's facing and its left."""
    angle = np.radians(yaw(joints))[:-1]
    step = np.diff(joints[:, 0, [0, 2]], axis=0)
    forward = step[:, 0] * np.sin(angle) + step[:, 1] * np.cos(angle)
    left = step[:, 0] * np.cos(angle) - step[:, 1] * np.sin(angle)
    return float(forward.sum()), float(left.sum())


def direction(joints: np.ndarray, which: str) -> Verdict:
    forward, left = body_travel(joints)
    along = {"forward": forward, "backward": -forward, "left": left, "right": -left}[which]
    total = float(np.hypot(forward, left))
    passed = along >= MIN_TRAVEL and along >= DOMINANT * total
    return Verdict(passed, along, f"{which} {along:.2f} m of {total:.2f} m")


def turn(joints: np.ndarray, which: str) -> Verdict:
    change = yaw(joints) - yaw(joints)[0]
    most = {"left": change.max(), "right": -change.min(), "around": np.abs(change).max()}[which]
    need = AROUND_DEG if which == "around" else TURN_DEG
    return Verdict(bool(most >= need), float(most), f"turned {which} {most:.0f}°")


def _distance(joints: np.ndarray) -> np.ndarray:
    return np.linalg.norm(joints[:, 0, [0, 2]] - joints[0, 0, [0, 2]], axis=-1)


def travel(joints: np.ndarray, which: str) -> Verdict:
    d = _distance(joints)
    if which == "return":
        passed = d.max() >= RETURN_OUT and d[-1] <= 0.5 * d.max()
        return Verdict(bool(passed), float(d[-1]), f"out {d.max():.2f} m, ends {d[-1]:.2f} m from the start")
    if which == "in_place":
        return Verdict(bool(d.max() <= IN_PLACE), float(d.max()), f"strays {d.max():.2f} m")
    return Verdict(bool(d[-1] >= AWAY), float(d[-1]), f"ends {d[-1]:.2f} m away")


def circle(joints: np.ndarray) -> Verdict:
    a = yaw(joints)
    sweep = float(a.max() - a.min())
    path = float(np.linalg.norm(np.diff(joints[:, 0, [0, 2]], axis=0), axis=-1).sum())
    need = max(CIRCLE_MIN_DEG, CIRCLE_RATE * (len(joints) - 1) / FPS)
    return Verdict(sweep >= need and path >= CIRCLE_PATH, sweep,
                   f"facing sweeps {sweep:.0f}° (needs {need:.0f}°) over {path:.1f} m")


def _dips(joints: np.ndarray) -> list[tuple[int, int]]:
    """Runs of the pelvis below :data:`CROUCH` of standing, ≥ 3 frames; runs less than :data:`HOLD_FRAMES` apart
    are one dip (a pelvis hovering at the threshold)."""
    low = [r for r in runs(joints[:, 0, 1] < CROUCH * standing_height(joints)) if r[1] - r[0] >= 3]
    merged: list[tuple[int, int]] = []
    for r in low:
        if merged and r[0] - merged[-1][1] < HOLD_FRAMES:
            merged[-1] = (merged[-1][0], r[1])
        else:
            merged.append(r)
    return merged


def _held(mask: np.ndarray) -> bool:
    return any(e - s >= HOLD_FRAMES for s, e in runs(mask))


def jumps(joints: np.ndarray) -> list[tuple[int, int]]:
    """Flights ``[start, end)`` of at least :data:`JUMP_FRAMES` frames."""
    return [f for f in flights(joints) if f[1] - f[0] >= JUMP_FRAMES]


def count(joints: np.ndarray, what: str, n: int) -> Verdict:
    found = len(jumps(joints)) if what == "jumps" else len(_dips(joints))
    return Verdict(found == n, float(found), f"{found} {what}")


def side(joints: np.ndarray, limb: str, which: str) -> Verdict:
    mine, other = (_LEFT, _RIGHT) if which == "left" else (_RIGHT, _LEFT)
    if limb == "leg":
        a, b = joints[:, mine["leg"], 1].max(), joints[:, other["leg"], 1].max()
        passed = a >= KICK_HEIGHT and a >= b + SIDE_MARGIN
        return Verdict(bool(passed), float(a - b), f"{which} ankle up {a:.2f} m, other {b:.2f} m")
    rel = joints[:, :, 1] - joints[:, :1, 1]
    a, b = rel[:, mine["arm"]].max(), rel[:, other["arm"]].max()
    above = (joints[:, mine["arm"], 1] - joints[:, _SHOULDER[which], 1]).max()
    passed = above >= -SHOULDER_SLACK and a >= b + SIDE_MARGIN
    return Verdict(bool(passed), float(a - b), f"{which} wrist {a - b:+.2f} m over the other, {above:+.2f} m over its shoulder")


def posture(joints: np.ndarray, which: str) -> Verdict:
    stand = standing_height(joints)
    pelvis = joints[:, 0, 1]
    end = float(pelvis[-int(FPS):].mean()) / stand
    low = float(pelvis.min())
    if which == "pick_up":
        wrist = float(joints[:, [20, 21], 1].min())
        return Verdict(wrist <= PICK_WRIST and low > LIE, wrist, f"lowest wrist {wrist:.2f} m")
    need = {"sit_stand": SIT * stand, "sit": SIT * stand, "crouch": CROUCH * stand, "lie_get_up": LIE}[which]
    down = _held(pelvis <= need) if which != "crouch" else low <= need
    passed = down and (end >= STOOD if which in ("sit_stand", "lie_get_up") else True)
    if which == "sit":
        passed = passed and end <= STOOD
    return Verdict(bool(passed), low, f"pelvis down to {low:.2f} m ({low / stand:.0%} of standing), ends at {end:.0%}")


def event_frame(joints: np.ndarray, event: str) -> int | None:
    """First frame of ``event`` (:data:`EVENTS`), or None when the motion never does it."""
    stand = standing_height(joints)
    if event == "travel":
        hit = _distance(joints) >= MIN_TRAVEL
    elif event == "jump":
        found = jumps(joints)
        return found[0][0] if found else None
    elif event in ("sit", "crouch", "lie"):
        hit = joints[:, 0, 1] <= {"sit": SIT * stand, "crouch": CROUCH * stand, "lie": LIE}[event]
    elif event == "raise":
        hit = (joints[:, [20, 21], 1] > joints[:, [15], 1]).any(axis=1)
    elif event == "turn":
        hit = np.abs(yaw(joints) - yaw(joints)[0]) >= TURN_DEG
    else:
        raise SimdiffError(f"unknown event {event!r}; expected one of {', '.join(EVENTS)}")
    frames = np.flatnonzero(hit)
    return int(frames[0]) if frames.size else None


def order(joints: np.ndarray, first: str, then: str) -> Verdict:
    a, b = event_frame(joints, first), event_frame(joints, then)
    passed = a is not None and b is not None and a < b
    seen = lambda f: "never" if f is None else f"{f / FPS:.1f} s"
    return Verdict(passed, float(-1 if a is None or b is None else b - a), f"{first} {seen(a)}, {then} {seen(b)}")


def speed_ratio(joints: np.ndarray, reference: np.ndarray, which: str) -> Verdict:
    def speed(j: np.ndarray) -> float:
        return float(np.linalg.norm(np.diff(j[:, 0, [0, 2]], axis=0), axis=-1).sum() * FPS / (len(j) - 1))

    moved = [float(_distance(j).max()) for j in (joints, reference)]
    if min(moved) < MIN_TRAVEL:
        return Verdict(False, 0.0, f"no pace to compare: travels {moved[0]:.2f} m, the plain wording {moved[1]:.2f} m")
    ratio = speed(joints) / speed(reference)
    passed = ratio <= SLOWER if which == "slower" else ratio >= FASTER
    return Verdict(bool(passed), ratio, f"pelvis speed ×{ratio:.2f} of the plain wording")


_NESTED = ({"sit", "crouch"}, {"sit", "lie"}, {"crouch", "lie"})
"""Event pairs whose order is fixed by their thresholds (a pelvis below sitting height is below crouching height)."""
_ARGS = {"direction": ("forward", "backward", "left", "right"), "turn": ("left", "right", "around"),
         "travel": ("return", "in_place", "away"), "posture": ("sit_stand", "lie_get_up", "crouch", "pick_up", "sit"),
         "speed": ("slower", "faster")}


def thresholds() -> dict[str, object]:
    """What a verdict depends on: every threshold of this module and of :mod:`simdiff.motion.flight` by name, and a
    digest of both modules' source (a cached measurement made with other values or code is measured again)."""
    import hashlib
    import inspect

    from simdiff.motion import flight

    out: dict[str, object] = {}
    for module, prefix in ((globals(), ""), (vars(flight), "flight.")):
        out.update({prefix + k: float(v) for k, v in module.items() if k.isupper() and isinstance(v, (int, float))})
    source = inspect.getsource(inspect.getmodule(thresholds)) + inspect.getsource(flight)
    out["source"] = hashlib.sha256(source.encode("utf-8")).hexdigest()[:16]
    return out


def parse_check(check: str) -> tuple[str, str]:
    """``"name:argument"`` → (name, argument); a one-line :class:`SimdiffError` naming a bad check."""
    name, _, arg = str(check).partition(":")
    ok = name in _ARGS and arg in _ARGS[name]
    if name == "circle":
        ok = arg == ""
    elif name == "count":
        what, _, n = arg.partition("=")
        ok = what in ("jumps", "squats") and n.isdigit()
    elif name == "side":
        limb, _, which = arg.partition("=")
        ok = limb in ("leg", "arm") and which in ("left", "right")
    elif name == "order":
        first, _, then = arg.partition("<")
        ok = first in EVENTS and then in EVENTS and first != then and {first, then} not in _NESTED
    if not ok:
        raise SimdiffError(f"unknown check {check!r}; expected e.g. direction:backward, turn:around, travel:in_place, "
                           "circle:, count:jumps=2, side:leg=left, posture:sit_stand, order:travel<jump, speed:slower")
    return name, arg


def run_check(joints: np.ndarray, check: str, reference: np.ndarray | None = None) -> Verdict:
    """The verdict of ``check`` (see the module docstring) on ``joints``; ``reference`` for ``speed:``."""
    name, arg = parse_check(check)
    for motion in (joints,) if reference is None else (joints, reference):
        if not np.all(np.isfinite(np.asarray(motion, dtype=np.float64))):
            raise SimdiffError(f"check {check!r}: the motion holds NaN or infinite joint positions")
    j = floored(joints)
    if name == "direction":
        return direction(j, arg)
    if name == "turn":
        return turn(j, arg)
    if name == "travel":
        return travel(j, arg)
    if name == "circle":
        return circle(j)
    if name == "count":
        what, _, n = arg.partition("=")
        return count(j, what, int(n))
    if name == "side":
        limb, _, which = arg.partition("=")
        return side(j, limb, which)
    if name == "posture":
        return posture(j, arg)
    if name == "order":
        first, _, then = arg.partition("<")
        return order(j, first, then)
    if reference is None:
        raise SimdiffError(f"check {check!r} needs a reference motion (the same seed without the speed word)")
    return speed_ratio(j, floored(reference), arg)
