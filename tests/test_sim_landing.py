"""Flight phases: landing synchronisation, support inference, falls judged on the pose, φ in the feed-forward."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("mujoco")

from simdiff.sim import synthetic  # noqa: E402
from simdiff.sim.retarget import make_reference  # noqa: E402
from simdiff.sim.retarget.contacts import infer_support  # noqa: E402
from simdiff.sim.env import Environment  # noqa: E402
from simdiff.sim.humanoid import load_model  # noqa: E402
from simdiff.sim.rollout import rollout  # noqa: E402
from simdiff.sim.tracker import LandingSync  # noqa: E402


def _contacts(pattern: str) -> np.ndarray:
    """'x' = both feet down, '.' = airborne."""
    return np.array([[c == "x"] * 4 for c in pattern])


def test_landing_sync_early_touchdown_takes_the_landing_pose():
    c = _contacts("xxx.....xxx")
    vz = np.array([0, 0, 1, 1, 0.5, 0, -0.5, -1, -1, 0, 0], dtype=float)
    sync = LandingSync(c, vz, max_hold=4)
    assert [sync(k, True) for k in range(3)] == [0, 1, 2]
    assert sync(3, False) == 3 and sync(4, False) == 4  # flying with the reference
    assert sync(5, True) == 5  # reference still rising (vz = 0): no early landing
    assert sync(6, True) == 8  # simulation down while the reference descends: touchdown frame
    assert sync(7, True) == 8
    assert sync(8, True) == 8 and sync(9, True) == 9  # back on the clock


def test_landing_sync_late_touchdown_holds_the_touchdown_frame_bounded():
    c = _contacts("xx...xxxxxxxx")
    sync = LandingSync(c, np.zeros(len(c)), max_hold=3)
    assert sync(0, True) == 0
    for k in (2, 3, 4):
        assert sync(k, False) == k
    assert [sync(k, False) for k in (5, 6, 7, 8, 9)] == [5, 5, 5, 8, 9]  # hold 3 frames, then the clock
    assert sync(10, True) == 10
    # a simulation that never left the floor is never held
    sync = LandingSync(c, np.zeros(len(c)), max_hold=3)
    assert [sync(k, True) for k in range(len(c))] == list(range(len(c)))


def test_infer_support_only_where_the_body_is_held_up():
    fps, T = 20.0, 40
    t = np.arange(T) / fps
    h = np.full((T, 4), 0.3)
    h[:, 1] = 0.08  # left toe box 8 cm up, nothing scheduled
    contact = np.zeros((T, 4), dtype=bool)
    xy = np.zeros((T, 4, 2))
    free_fall = 1.0 + 2.0 * t - 0.5 * 9.81 * t**2
    assert not infer_support(contact, h, xy, free_fall, fps, 0.5, 0.15).any()
    held = 0.9 + 0.02 * np.sin(2 * np.pi * t)  # slow bobbing: needs the floor
    out = infer_support(contact, h, xy, held, fps, 0.5, 0.15)
    assert out[:, 1].all() and not out[:, [0, 2, 3]].any()
    assert not infer_support(contact, h + 0.2, xy, held, fps, 0.5, 0.15).any()  # out of reach
    sched = contact.copy()
    sched[:, 2] = True  # already supported by the schedule: nothing added
    assert not infer_support(sched, h, xy, held, fps, 0.5, 0.15).any()
    assert not infer_support(contact, h, xy, held, fps, 0.0, 0.15).any()  # off
    sliding = xy.copy()
    sliding[:, 1, 0] = 1.0 * t  # the toe slides at 1 m/s: not a support
    assert not infer_support(contact, h, sliding, held, fps, 0.5, 0.15).any()


def test_despike_keeps_a_fast_first_frame():
    from simdiff.sim.retarget.filtering import despike

    j = synthetic.walk_in_place(30).astype(float)
    j[..., 2] += 4.3 * np.arange(30)[:, None] / 20.0  # a 4.3 m/s run: 0.21 m a frame
    out = despike(j, 0.25)
    assert np.allclose(out, j)  # before: frame 0 was taken for a glitch and frozen
    bad = j.copy()
    bad[0, 20] += [0.0, 0.0, 0.7]
    bad[-1, 10] += [0.5, 0.0, 0.0]
    out = despike(bad, 0.25)
    assert np.linalg.norm(out[0, 20] - j[0, 20]) < 0.05
    assert np.linalg.norm(out[-1, 10] - j[-1, 10]) < 0.05


def test_feedforward_uses_the_gravity_of_phi():
    m = load_model()
    joints = synthetic.squat(40)
    earth = make_reference(m, joints)
    moon = make_reference(m, joints, gravity=-1.62)
    assert np.allclose(m.opt.gravity, [0, 0, -9.81])  # the model is left as it was
    ratio = np.abs(moon.tau_ff).sum() / np.abs(earth.tau_ff).sum()
    assert 0.05 < ratio < 0.5  # holding the body up costs about g


@pytest.fixture(scope="module")
def jump():
    return synthetic.vertical_jump(height=0.15)


def test_jump_under_low_gravity_flies_higher_and_is_not_a_fall(jump):
    m = load_model()
    apex, air = {}, {}
    for g in (-9.81, -3.0):
        res = rollout(m, make_reference(m, jump, gravity=g), Environment(g), audit=True)
        assert res.status == "ok", g
        assert not res.violations
        assert not np.any(res.residual[res.airborne])
        apex[g] = res.qpos[:, 2].max()
        air[g] = res.airborne.sum()
    assert apex[-3.0] > apex[-9.81] + 0.05
    assert air[-3.0] > air[-9.81]


def test_second_derivative5_is_scipys_quadratic_savgol_and_exact_for_free_fall():
    from scipy.signal import savgol_filter

    from simdiff.sim.retarget.contacts import second_derivative5

    rng = np.random.default_rng(0)
    for n in (5, 6, 41):
        x = rng.normal(size=n)
        want = savgol_filter(x, 5, 2, deriv=2, delta=1.0 / 20.0, mode="interp")
        np.testing.assert_allclose(second_derivative5(x, 20.0), want, rtol=1e-9, atol=1e-9)
    t = np.arange(30) / 20.0
    np.testing.assert_allclose(second_derivative5(1.0 + 2.0 * t - 0.5 * 9.81 * t**2, 20.0), -9.81, atol=1e-9)


def test_stance_anchor_shift_cancels_planted_drift_and_keeps_steps():
    from simdiff.sim.retarget.contacts import stance_anchor_shift

    T = 11
    xy = np.zeros((T, 4, 2))
    xy[:, :, 0] = 0.01 * np.arange(T)[:, None]  # every box drifts +1 cm/frame
    contact = np.ones((T, 4), dtype=bool)
    shift = stance_anchor_shift(contact, xy)
    assert shift.shape == (T, 2) and np.all(shift[0] == 0)
    np.testing.assert_allclose(xy[:, :, 0] + shift[:, :1], 0.0, atol=1e-12)  # planted: held where it landed
    # no contact: nothing moves; one planted foot drifting while the other swings: only the planted one counts
    np.testing.assert_array_equal(stance_anchor_shift(np.zeros((T, 4), dtype=bool), xy), 0.0)
    step = xy.copy()
    step[:, 2:, 0] = 0.05 * np.arange(T)[:, None]  # right foot swings forward 5 cm/frame
    half = np.zeros((T, 4), dtype=bool)
    half[:, :2] = True
    np.testing.assert_allclose(stance_anchor_shift(half, step)[:, 0], -0.01 * np.arange(T), atol=1e-12)
    # a contact that lasts one frame has no displacement to cancel
    blink = np.zeros((T, 4), dtype=bool)
    blink[5] = True
    np.testing.assert_array_equal(stance_anchor_shift(blink, xy), 0.0)


def test_skating_support_is_the_lowest_box_where_nothing_is_planted():
    from simdiff.sim.retarget.contacts import skating_support

    contact = np.zeros((4, 4), dtype=bool)
    contact[0, 1] = True  # frame 0 has a planted box: nothing added
    height = np.array([[0.01, 0.0, 0.1, 0.1],  # planted
                       [0.03, 0.025, 0.2, 0.01],  # gliding on the floor: R toe is lowest
                       [0.3, 0.2, 0.1, 0.05],  # flight (lowest sole 5 cm ≥ reach 4 cm)
                       [0.0, 0.005, 0.1, 0.1]])  # a flat left foot: heel and toe within 1 cm
    out = skating_support(contact, height, 0.04)
    assert out.dtype == bool and out.shape == (4, 4)
    assert out.tolist() == [[False] * 4, [False, False, False, True], [False] * 4, [True, True, False, False]]


def test_anchored_reference_holds_a_stand_that_glides_too_fast_to_count_as_planted():
    """A stand gliding 5 cm/frame (1 m/s, above the schedule's contact speed, as a generated run's
    stance foot does): no foot is planted, the lowest one anchors the body anyway."""
    from simdiff.sim.retarget import RetargetConfig

    glide = synthetic.standing(40)
    glide[..., 0] += 0.05 * np.arange(40)[:, None]
    model = load_model()
    plain = make_reference(model, glide)
    anchored = make_reference(model, glide, RetargetConfig(anchor_stance=True))
    travel = lambda ref: float(np.linalg.norm(ref.qpos[-1, :2] - ref.qpos[0, :2]))  # noqa: E731
    assert travel(plain) > 1.5
    assert travel(anchored) < 0.05


def test_anchored_reference_keeps_a_skating_stand_in_place():
    """A stand whose whole body glides 1 cm/frame on planted feet (what a generated 'jump in place'
    does): anchored, the reference's pelvis and feet stay put; unanchored it glides."""
    from simdiff.sim.retarget import RetargetConfig

    still = synthetic.standing(40)
    glide = still.copy()
    glide[..., 0] += 0.01 * np.arange(40)[:, None]
    model = load_model()
    plain = make_reference(model, glide)
    anchored = make_reference(model, glide, RetargetConfig(anchor_stance=True))
    travel = lambda ref: float(np.linalg.norm(ref.qpos[-1, :2] - ref.qpos[0, :2]))  # noqa: E731
    assert travel(plain) > 0.3
    assert travel(anchored) < 0.02
    feet = anchored.body_pos[:, [7, 8, 10, 11], :2]
    assert np.abs(feet - feet[:1]).max() < 0.02


def test_swing_lift_raises_only_fast_low_feet_off_contact():
    from simdiff.sim.retarget.contacts import swing_lift

    T = 15
    contact = np.zeros((T, 4), dtype=bool)
    contact[:, :2] = True  # left foot planted throughout
    contact[:3, 2:] = contact[12:, 2:] = True  # right foot down at both ends, swinging in between
    height = np.zeros((T, 4))  # ... and its swing scrapes the floor
    xy = np.zeros((T, 4, 2))
    xy[3:, 2:, 0] = 0.1 * np.arange(1, T - 2)[:, None]  # 2 m/s from frame 3
    xy[12:, 2:, 0] = xy[11, 2, 0]
    lift = swing_lift(contact, height, xy, 20.0, 0.02, 0.6, 1.2)
    assert lift.shape == (T, 2)
    np.testing.assert_array_equal(lift[:, 0], 0.0)  # a planted foot is never lifted
    np.testing.assert_array_equal(lift[contact[:, 2], 1], 0.0)
    np.testing.assert_allclose(lift[5:10, 1], 0.02, atol=1e-3)  # full clearance mid-swing
    assert np.all(np.diff(lift[3:7, 1]) >= 0)  # ramps in, tapered next to the contact
    assert lift[3, 1] <= 0.02 / 3 + 1e-9 and lift[11, 1] <= 0.02 / 3 + 1e-9
    # a foot already clear, one that moves slowly, or clearance 0: no lift
    np.testing.assert_array_equal(swing_lift(contact, height + 0.03, xy, 20.0, 0.02, 0.6, 1.2), 0.0)
    np.testing.assert_array_equal(swing_lift(contact, height, xy * 0.2, 20.0, 0.02, 0.6, 1.2), 0.0)
    np.testing.assert_array_equal(swing_lift(contact, height, xy, 20.0, 0.0, 0.6, 1.2), 0.0)
    # half the deficit when the sole is already 1 cm up
    np.testing.assert_allclose(swing_lift(contact, height + 0.01, xy, 20.0, 0.02, 0.6, 1.2)[5:10, 1], 0.01, atol=1e-3)


def test_the_stance_pass_lifts_the_feet_swing_lift_asks_for(monkeypatch):
    """Wiring: a lift of 3 cm asked for the right foot while it is raised 5 cm (off contact) raises
    the reference's right sole by about that much there; the planted left foot and the frames
    without lift stay as they were; clearance 0 (the augmentation) asks swing_lift for nothing."""
    import simdiff.sim.retarget.reference as reference
    from simdiff.sim.retarget import RetargetConfig, finish_retarget, foot_heights
    from simdiff.sim.retarget.config import FINISH_SWING_CLEARANCE

    asked = []

    def fake_lift(contact, height, xy, fps, clearance, lo, hi):
        asked.append(clearance)
        lift = np.zeros((len(contact), 2))
        if clearance > 0:
            lift[15:26, 1] = 0.03
        return lift

    monkeypatch.setattr(reference, "swing_lift", fake_lift)
    raised = synthetic.standing(40)
    raised[12:29, [8, 11], 1] += 0.05
    model = load_model()
    plain = make_reference(model, raised, RetargetConfig())
    lifted = make_reference(model, raised, RetargetConfig(swing_clearance=FINISH_SWING_CLEARANCE))
    assert asked == [0.0, FINISH_SWING_CLEARANCE]
    h_plain, _ = foot_heights(model, plain.qpos)
    h_lift, _ = foot_heights(model, lifted.qpos)
    t = np.arange(plain.num_frames) * plain.dt * 20.0  # input frame of each control frame
    mid, away = (t >= 17) & (t <= 23), (t <= 8) | (t >= 33)
    gain = h_lift[mid, 2:].min(axis=1) - h_plain[mid, 2:].min(axis=1)
    assert np.all(gain > 0.02) and np.all(gain < 0.04)
    np.testing.assert_allclose(h_lift[away], h_plain[away], atol=2e-3)
    np.testing.assert_allclose(h_lift[:, :2], h_plain[:, :2], atol=3e-3)
    assert finish_retarget().swing_clearance == FINISH_SWING_CLEARANCE and finish_retarget().anchor_stance
    assert finish_retarget(False) == RetargetConfig()


def test_the_finish_tracker_config_reaches_the_default_tracker(monkeypatch):
    """project(tracker_config=...) builds the default tracker from it (landing sync set by the flight clock)."""
    import simdiff.sim.rollout as rollout_module
    from simdiff.sim.flight import FlightConfig
    from simdiff.sim.project import project
    from simdiff.sim.tracker import (FINISH_LATE_FOOT, FINISH_LEAD, FINISH_MOVING_KP_XY, FINISH_MOVING_ROT_SCALE,
                                     BalanceConfig, PDTracker, finish_tracker_config)

    seen = []

    gains, scales = [], []

    class Recording(PDTracker):
        def __init__(self, config):
            seen.append(config)
            super().__init__(config)

        def kp_xy(self, k):
            gains.append(super().kp_xy(k))
            return gains[-1]

        def rot_scale(self, k):
            scales.append(super().rot_scale(k))
            return scales[-1]

    monkeypatch.setattr(rollout_module, "PDTracker", Recording)
    stand = synthetic.standing(12)
    project(stand, Environment(), tracker_config=finish_tracker_config(), flight=FlightConfig())
    project(stand, Environment())
    assert seen[0].lead == FINISH_LEAD and seen[0].landing_sync is False  # the flight clock syncs landings
    assert seen[0].balance.moving_kp_xy == FINISH_MOVING_KP_XY == 0.0  # no position pull while moving (skids)
    assert seen[0].balance.kp_xy == 20.0 and seen[0].balance.kd_xy == BalanceConfig().kd_xy > 0
    assert seen[0].balance.late_foot == FINISH_LATE_FOOT != "release"  # a late foot lands where it was placed
    assert seen[0].balance.moving_rot_scale == FINISH_MOVING_ROT_SCALE  # (None: full gains; measured, not adopted)
    assert seen[1].lead == 1.5 and seen[1].landing_sync is True
    assert seen[1].balance == BalanceConfig() and seen[1].balance.moving_kp_xy is None  # the augmentation's
    assert seen[1].balance.late_foot == "release" and seen[1].balance.moving_rot_scale is None
    assert gains and set(gains) == {20.0}  # the balance layer asks for its gain (a stand: never moving)
    assert scales and set(scales) == {1.0}  # and for its orientation-gain factor (full gains when standing)


def test_the_balance_position_gain_fades_while_the_reference_moves():
    """moving_kp_xy: kp_xy below moving_speed[0], moving_kp_xy above moving_speed[1], linear between;
    the finish's setting, and gravity scaling keeps it proportional."""
    from types import SimpleNamespace

    from simdiff.sim.strength import scale_balance
    from simdiff.sim.tracker import BalanceConfig, PDTracker, PDTrackerConfig, finish_tracker_config

    vel = np.zeros((5, 3))
    vel[:, 0] = [0.0, 0.3, 0.45, 0.6, 2.0]
    vel[2, :2] = [0.27, 0.36]  # 0.45 m/s diagonally
    ref = SimpleNamespace(com_vel=vel)
    t = PDTracker(finish_tracker_config())
    t.ref = ref
    np.testing.assert_allclose([t.kp_xy(k) for k in range(5)], [20.0, 20.0, 10.0, 0.0, 0.0], atol=1e-9)
    t = PDTracker(PDTrackerConfig(balance=BalanceConfig(moving_kp_xy=4.0, moving_speed=(1.0, 3.0))))
    t.ref = ref
    np.testing.assert_allclose([t.kp_xy(k) for k in range(5)], [20.0, 20.0, 20.0, 20.0, 12.0], atol=1e-9)
    t = PDTracker(PDTrackerConfig())  # the augmentation's: one gain throughout
    t.ref = ref
    assert [t.kp_xy(k) for k in range(5)] == [20.0] * 5
    half = scale_balance(PDTrackerConfig(balance=BalanceConfig(moving_kp_xy=4.0)), 0.5).balance
    assert (half.kp_xy, half.moving_kp_xy) == (10.0, 2.0)


def test_the_pelvis_orientation_gains_soften_while_the_reference_moves():
    """moving_rot_scale: factor 1 below moving_speed[0], the setting above moving_speed[1], linear between;
    the torque the balance layer asks of the stance legs scales with it; out-of-range values are refused."""
    from types import SimpleNamespace

    from simdiff.errors import SimdiffError
    from simdiff.sim.tracker import BalanceConfig, PDTracker, PDTrackerConfig

    vel = np.zeros((5, 3))
    vel[:, 1] = [0.0, 0.3, 0.45, 0.6, 2.0]
    ref = SimpleNamespace(com_vel=vel)
    t = PDTracker(PDTrackerConfig(balance=BalanceConfig(moving_rot_scale=0.4)))
    t.ref = ref
    np.testing.assert_allclose([t.rot_scale(k) for k in range(5)], [1.0, 1.0, 0.7, 0.4, 0.4], atol=1e-12)
    t = PDTracker(PDTrackerConfig())  # the augmentation's: full gains throughout
    t.ref = ref
    assert [t.rot_scale(k) for k in range(5)] == [1.0] * 5
    for bad in (-0.1, 1.5, float("nan")):
        with pytest.raises(SimdiffError, match="moving_rot_scale must be in"):
            BalanceConfig(moving_rot_scale=bad)


def test_the_orientation_factor_scales_the_stance_torque():
    """A slightly tilted pelvis on a standing reference: the stance-leg torque the balance layer adds for
    the orientation error scales with rot_scale (the COM terms held at zero; the tilt small enough that
    the feet's centre-of-pressure bounds do not clip the moment)."""
    import mujoco

    from simdiff.sim.humanoid import model_index
    from simdiff.sim.tracker import BalanceConfig, PDTracker, PDTrackerConfig

    model = load_model()
    ref = make_reference(model, synthetic.standing(20))
    data = mujoco.MjData(model)
    data.qpos[:] = ref.qpos[0]
    data.qpos[3:7] = [np.cos(0.005), np.sin(0.005), 0.0, 0.0]  # 0.01 rad roll
    mujoco.mj_forward(model, data)
    cfg = BalanceConfig(kp_xy=0.0, kd_xy=0.0, kp_z=0.0, kd_z=0.0, kd_rot=0.0, step_gain=0.0)
    t = PDTracker(PDTrackerConfig(balance=cfg))
    t.reset(model, data, ref, model_index(model))
    on = np.ones(4, dtype=bool)
    full = np.zeros(69)
    t._balance(data, 5, on, full)
    t.rot_scale = lambda k: 0.5
    half = np.zeros(69)
    t._balance(data, 5, on, half)
    assert np.abs(full).max() > 1e-4
    np.testing.assert_allclose(half, 0.5 * full, atol=1e-12)


@pytest.mark.parametrize("mode", ["release", "hold", "place"])
def test_a_late_swing_foot_drops_holds_or_keeps_placing(mode):
    """late_foot: the reference has the right foot down at frame 2 while the simulated one is still
    in the air. "release" stops placing it, "hold" repeats the last capture-point shift (whatever the
    error now), "place" goes on computing it (twice the error: twice the shift, below step_max); a
    foot that touches the floor ends its placement."""
    import mujoco

    from simdiff.sim.humanoid import model_index
    from simdiff.sim.tracker import BalanceConfig, PDTracker, PDTrackerConfig

    model = load_model()
    ref = make_reference(model, synthetic.standing(20))
    ref.contact = ref.contact.copy()
    ref.contact[1, 2:] = False  # frame 1: the reference's right foot in swing
    ref.contact[2, 2:] = True  # frame 2: down
    data = mujoco.MjData(model)
    data.qpos[:] = ref.qpos[0]
    mujoco.mj_forward(model, data)
    t = PDTracker(PDTrackerConfig(balance=BalanceConfig(late_foot=mode)))
    t.reset(model, data, ref, model_index(model))
    e, ev = np.array([0.05, 0.02, 0.0]), np.zeros(3)
    swing = np.zeros(69)
    t._place_swing_foot(data, 0, 1, e, ev, 0.9, swing)  # aims at frame 1: in swing, placed
    assert np.abs(swing).max() > 1e-3 and np.count_nonzero(swing) == 4  # right hip xyz + knee
    late = np.zeros(69)
    t._place_swing_foot(data, 1, 1, 2 * e, ev, 0.9, late)  # aims at frame 2: the reference has it down
    expected = {"release": np.zeros(69), "hold": swing, "place": 2 * swing}[mode]
    np.testing.assert_allclose(late, expected, atol=1e-12)
    t._balance(data, 1, np.array([True, True, True, True]), np.zeros(69))  # both feet on the floor
    assert t.placed == [None, None]
    after = np.zeros(69)
    t._place_swing_foot(data, 1, 1, e, ev, 0.9, after)
    expected = {"release": np.zeros(69), "hold": np.zeros(69), "place": swing}[mode]
    np.testing.assert_allclose(after, expected, atol=1e-12)


def test_late_foot_rejects_an_unknown_mode():
    from simdiff.errors import SimdiffError
    from simdiff.sim.tracker import BalanceConfig

    with pytest.raises(SimdiffError, match="late_foot must be one of release, hold, place, got 'stay'"):
        BalanceConfig(late_foot="stay")
