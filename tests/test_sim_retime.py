"""The weak-gravity second try on a Froude-slowed source (simdiff.sim.retime, project(retime=...))."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from simdiff.errors import SimdiffError
from simdiff.sim.retime import RetimeConfig, better, stretch


def test_scale_is_froude_under_weak_gravity_and_one_otherwise():
    c = RetimeConfig()
    assert c.scale(-9.81) == 1.0 and c.scale(-15.0) == 1.0 and c.scale(-20.0) == 1.0
    assert c.scale(-9.81 / 4) == pytest.approx(2.0)
    assert c.scale(-1.6) == pytest.approx(math.sqrt(9.81 / 1.6))
    assert c.scale(-0.1) == 4.0  # max_scale caps it
    assert RetimeConfig(exponent=1.0).scale(-9.81 / 2) == pytest.approx(2.0)
    with pytest.raises(SimdiffError, match="exponent"):
        RetimeConfig(exponent=0.0)
    with pytest.raises(SimdiffError, match="max_scale"):
        RetimeConfig(max_scale=0.5)


def test_stretch_slows_the_motion_by_the_scale_with_linear_interpolation():
    rng = np.random.default_rng(0)
    j = rng.normal(size=(5, 22, 3)).astype(np.float32)
    s = stretch(j, 2.0)
    assert s.shape == (9, 22, 3) and s.dtype == np.float32
    np.testing.assert_allclose(s[::2], j, atol=1e-6)  # every second frame is a source frame
    np.testing.assert_allclose(s[1], 0.5 * (j[0] + j[1]), atol=1e-6)
    np.testing.assert_allclose(stretch(j, 1.0), j)
    assert stretch(j, 2.5).shape[0] == 11  # round((5 - 1) * 2.5) + 1
    with pytest.raises(SimdiffError, match="scale"):
        stretch(j, 0.5)
    with pytest.raises(SimdiffError, match="shape"):
        stretch(j[:1], 2.0)


def test_retry_rule_and_choice():
    c = RetimeConfig(pose_trigger=6.5)
    assert c.should_retry("fell", 1.0) and c.should_retry("unstable", float("nan"))
    assert c.should_retry("ok", 7.0) and not c.should_retry("ok", 6.0)
    assert not c.should_retry("ok", float("nan"))  # no normaliser: only falls trigger
    assert better(("fell", 3.0), ("ok", 9.0))  # a finished rollout beats a fall
    assert not better(("ok", 9.0), ("fell", 3.0))
    assert better(("ok", 9.0), ("ok", 5.0)) and not better(("ok", 5.0), ("ok", 9.0))
    assert not better(("ok", 5.0), ("ok", float("nan")))


@pytest.fixture(scope="module")
def sim():
    pytest.importorskip("mujoco")
    from simdiff.motion.normalize import Normalizer
    from simdiff.sim import synthetic
    from simdiff.sim.humanoid import load_model

    norm = Normalizer(np.zeros(263, dtype=np.float32), np.full(263, 0.05, dtype=np.float32))
    return load_model(), synthetic.walk_in_place(frames=40), norm


def test_project_makes_the_second_try_only_under_weak_gravity_and_keeps_the_better(sim):
    from simdiff.sim.env import Environment
    from simdiff.sim.flight import FlightConfig
    from simdiff.sim.project import project

    model, walk, norm = sim
    force_retry = RetimeConfig(pose_trigger=-1.0)  # every finished rollout "strayed": always a second try
    g = -9.81 / 4  # scale 2
    kw = dict(model=model, normalizer=norm, flight=FlightConfig())
    first_out, first = project(walk, Environment(gravity=g), **kw)
    slow_out, slow = project(stretch(walk, 2.0), Environment(gravity=g), **kw)
    out, info = project(walk, Environment(gravity=g), retime=force_retry, **kw)
    assert info.attempts == 2 and info.n_frames == walk.shape[0]
    assert info.cpu_s >= first.cpu_s
    if better((first.status, first.d_l2_pose), (slow.status, slow.d_l2_pose)):
        assert info.retime_scale == pytest.approx(2.0)
        np.testing.assert_array_equal(out, slow_out)  # deterministic: the same rollout as tracking the slowed source
        assert info.d_l2_pose == slow.d_l2_pose
        assert info.time_warp == pytest.approx(len(slow_out) / walk.shape[0])
    else:
        assert info.retime_scale == 1.0
        np.testing.assert_array_equal(out, first_out)
    # One try: without retime, at Earth gravity, and when the first rollout is good enough.
    assert project(walk, Environment(gravity=-9.81), retime=force_retry, **kw)[1].attempts == 1
    assert first.attempts == 1 and first.retime_scale == 1.0
    lenient = RetimeConfig(pose_trigger=1e9)
    if first.status == "ok":
        _, info_l = project(walk, Environment(gravity=g), retime=lenient, **kw)
        assert info_l.attempts == 1 and info_l.d_l2_pose == first.d_l2_pose


def test_augment_settings_record_retime_and_old_runs_resume_only_without_it(tmp_path):
    from dataclasses import asdict

    from simdiff.data.augment.run import SETTINGS_NAME, AugmentConfig, _check_settings

    assert AugmentConfig().settings()["retime"] == asdict(RetimeConfig())
    assert "retime" not in AugmentConfig(retime=False).settings()
    old = AugmentConfig(retime=False)
    (tmp_path / SETTINGS_NAME).write_text(json.dumps({**old.settings(), "condition_list": []}))
    _check_settings(tmp_path, old, [])  # a run made before retiming resumes with --no-retime
    with pytest.raises(SimdiffError, match=r"different settings \(retime\)"):
        _check_settings(tmp_path, AugmentConfig(), [])


def test_cli_no_retime_flag_reaches_the_config(monkeypatch, tmp_path):
    import simdiff.data.augment.run as run_mod
    from simdiff.cli.main import main

    seen = {}

    def fake_augment(corpus, out, config, progress=True):
        seen["retime"] = config.retime
        return {"kept_fraction": None, "filter": {}, "kept": 0, "pairs": 0, "clips": 0}

    monkeypatch.setattr(run_mod, "augment", fake_augment)
    for flags, expected in (([], True), (["--no-retime"], False)):
        main(["data", "augment", "--corpus", str(tmp_path), "--out", str(tmp_path / "o"), *flags])
        assert seen["retime"] is expected
