"""``simdiff audit`` and :mod:`simdiff.eval.audit`: metrics, inverse-dynamics residual, tracking, reports."""

from __future__ import annotations

import json

import numpy as np
import pytest

pytest.importorskip("mujoco")

from simdiff.cli.main import main  # noqa: E402
from simdiff.errors import SimdiffError  # noqa: E402
from simdiff.eval.audit import FORCE_THRESHOLD_MG, audit_motion, plot_audit, reference_residual  # noqa: E402
from simdiff.motion.synthetic import walk  # noqa: E402
from simdiff.sim import synthetic  # noqa: E402
from simdiff.sim.env import Environment  # noqa: E402

OVER = f"frac_over_{FORCE_THRESHOLD_MG:g}mg"
LIFT = np.array([0.0, 0.5, 0.0], dtype=np.float32)


@pytest.fixture(scope="module")
def walk40() -> np.ndarray:
    return walk(40)


@pytest.fixture(scope="module")
def walk_audit(walk40):
    return audit_motion(walk40, name="walk")


def test_audit_synthetic_walk(walk_audit, walk40):
    a = walk_audit
    assert a.n_frames == 40 and a.duration_s == pytest.approx(1.95) and a.env == (-9.81, 0.0, 0.0)
    m = a.metrics
    # the procedural walk moves its root at constant speed while the feet swing: its feet slide
    assert m["penetration"] == 0.0 and m["sliding"] > 1.0 and m["skate_ratio"] > 0.2
    r = a.reference
    # sliding feet are never planted long enough to push: the root needs about its weight, mostly
    assert r["contact_frac"] < 0.5 and r[OVER] > 0.8 and 0.7 < r["force_mean_mg"] < 1.5
    assert r["force_p90_mg"] <= r["force_peak_mg"] and r["torque_mean_nm"] > 10
    assert r["mass_kg"] == pytest.approx(72.0, abs=0.5)
    assert len(a.series.t) == len(a.series.force_mg) == 60  # 1.95 s at 30 Hz, last frame covered
    t = a.tracking
    assert t is not None and t["status"] in ("ok", "fell", "unstable") and t["success"] == (t["status"] == "ok")
    assert a.rollout.shape == (t["n_out"], 22, 3) and 2 <= t["n_out"] <= 40
    assert t["err_mm"] > 0 and t["cpu_s"] > 0 and t["residual_bound_mg"] == 0.5
    assert (t["fall_frame"] is None) == t["success"]


def test_reference_residual_matches_the_simulators_screen(walk40):
    """Under Earth gravity the audit's screen is the one ``make_reference`` computes."""
    from simdiff.sim.retarget import make_reference
    from simdiff.sim.humanoid import load_model, model_index

    model = load_model()
    feas = make_reference(model, walk40).feasibility(model_index(model).mass, 9.81)
    summary, _ = reference_residual(walk40, Environment())
    assert summary["force_p90_mg"] == pytest.approx(feas["force_p90_mg"], rel=1e-9)
    assert model.opt.gravity[2] == pytest.approx(-9.81)  # the cached model is left alone


def test_floating_walk(walk_audit, walk40):
    """A walk lifted 0.5 m: the floating metric rises by 500 mm; the reference is put back on the floor."""
    lifted = audit_motion(walk40 + LIFT, name="float", track=False)
    assert lifted.tracking is None and lifted.rollout is None
    assert lifted.metrics["floating"] - walk_audit.metrics["floating"] == pytest.approx(500.0, abs=1.0)
    assert lifted.metrics["floating"] > 500.0
    shift = lifted.reference["ground_shift_m"] - walk_audit.reference["ground_shift_m"]
    assert shift == pytest.approx(-0.5, abs=0.01)
    assert lifted.reference["force_p90_mg"] == pytest.approx(walk_audit.reference["force_p90_mg"], abs=0.02)


def test_levitating_motion_needs_external_force():
    """A squat is supported by its feet; the same squat rising 0.5 m into the air is not."""
    squat = synthetic.squat(40)
    ok, _ = reference_residual(squat, Environment())
    assert ok["force_p90_mg"] < 0.02 and ok[OVER] == 0.0 and ok["contact_frac"] == 1.0
    rise = squat + np.linspace(0, 0.5, 40, dtype=np.float32)[:, None, None] * LIFT / 0.5
    bad, series = reference_residual(rise, Environment())
    assert bad["force_p90_mg"] > 1.0 and bad[OVER] > 0.3 and bad["contact_frac"] < 0.8
    # the residual is large exactly where no foot touches the floor
    air = ~series.contact
    assert air.any() and np.median(series.force_mg[air]) > 0.8


def test_gravity_scales_the_residual_force():
    """Airborne frames need m·|g_z| whatever g_z is: the fraction of m·|g_z| stays about 1."""
    rise = synthetic.squat(30) + np.linspace(0, 0.5, 30, dtype=np.float32)[:, None, None] * LIFT / 0.5
    earth, se = reference_residual(rise, Environment(-9.81))
    moon, sm = reference_residual(rise, Environment(-1.62))
    air = ~se.contact
    assert np.array_equal(se.contact, sm.contact)
    newtons_e = se.force_mg[air] * 72 * 9.81
    newtons_m = sm.force_mg[air] * 72 * 1.62
    assert np.median(newtons_e) > 3 * np.median(newtons_m)  # far less force needed on the moon


def test_audit_rejects_bad_input():
    with pytest.raises(SimdiffError, match="gravity"):
        audit_motion(walk(10), Environment(3.0), track=False)
    with pytest.raises(SimdiffError, match="3 frames"):
        audit_motion(walk(3), track=False)
    with pytest.raises(SimdiffError, match=r"\(10, 21, 3\)"):
        audit_motion(np.zeros((10, 21, 3)), track=False)


def test_report_table_json_and_plot(walk_audit, tmp_path):
    text = walk_audit.table()
    for needle in ("penetration", "floating", "sliding", "skate ratio", "p90", "peak", "N·m", "> 0.1 m·g",
                   "d_L2", "tracking error", "CPU"):
        assert needle in text
    d = json.loads(json.dumps(walk_audit.to_dict()))  # NaN (d_L2 without a normaliser) became null
    assert d["tracking"]["d_l2"] is None and d["reference"]["force_p90_mg"] > 0.5
    png = plot_audit(walk_audit, tmp_path / "a" / "walk.png")
    import imageio.v3 as iio

    img = iio.imread(png)
    assert img.ndim == 3 and img.shape[0] > 300 and img.shape[1] > 500 and img[..., :3].std() > 10


@pytest.fixture(scope="module")
def squat_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("audit") / "squat.npy"
    np.save(path, synthetic.squat(30))
    return path


def test_cli_audit_json_and_out(squat_file, tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["audit", str(squat_file), "--json", "--out", str(out), "--wind", "3", "0"]) == 0
    rec = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert rec["file"] == "squat.npy" and rec["env"] == [-9.81, 3.0, 0.0]
    assert rec["tracking"]["success"] is True and rec["tracking"]["d_l2"] > 0
    assert rec["reference"]["force_p90_mg"] < 0.05 and rec["metrics"]["floating"] < 20
    assert (out / "squat_audit.png").is_file() and (out / "squat_audit.json").is_file()
    assert np.load(out / "squat_rollout.npy").shape == (30, 22, 3)


def test_cli_audit_table_no_track(squat_file, capsys):
    assert main(["audit", str(squat_file), "--no-track", "--gravity", "-3.7"]) == 0
    text = capsys.readouterr().out
    assert "squat.npy" in text and "gravity -3.7" in text and "skipped" in text


@pytest.mark.parametrize(
    ("argv", "needle"),
    [
        (["missing.npy"], "missing.npy"),
        (["{squat}", "--gravity", "3"], "gravity"),
        (["{squat}", "--wind", "9", "9"], "wind"),
        (["{squat}", "--residual", "-1"], "--residual"),
        (["{squat}", "--render"], "--out"),
    ],
)
def test_cli_audit_errors_are_one_line(squat_file, tmp_path, capsys, argv, needle):
    argv = [a.replace("{squat}", str(squat_file)) if a == "{squat}" else a for a in argv]
    if argv[0] == "missing.npy":
        argv[0] = str(tmp_path / "missing.npy")
    assert main(["audit", *argv]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("simdiff: error:") and needle in err[0]


def test_the_gravity_of_a_flight_is_read_back(walk_audit):
    from simdiff.motion.synthetic import jump

    height, gravity = 0.4, -3.7
    airtime = float(np.sqrt(8 * height / -gravity))  # a ballistic jump under g −3.7
    audit = audit_motion(jump(frames=60, height=height, start=15, airtime=airtime), Environment(gravity, 0, 0),
                         track=False)
    assert audit.flight["gravity"] == pytest.approx(gravity, rel=0.02) and audit.flight["flights"] == 1
    assert audit.rollout_flight is None
    text = audit.table()
    assert "φ asks -3.7 m/s²" in text and f"{audit.flight['gravity']:9.2f} m/s²" in text
    assert walk_audit.flight is None and "no flight long enough to read" in walk_audit.table()
    assert walk_audit.gait["pelvis_speed"] > 0.5 and walk_audit.gait["cadence"] > 30
    assert "cadence" in walk_audit.table() and "duty factor" in walk_audit.table()
    assert json.loads(json.dumps(audit.to_dict()))["flight"]["gravity"] == pytest.approx(gravity, rel=0.02)
