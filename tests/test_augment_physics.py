"""Paired conditions, the confound check and the physics-signal measurements."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from simdiff.data.augment.conditions import paired_conditions
from simdiff.data.augment.confound import confound_check, motion_type
from simdiff.data.augment.signal import condition_bin, measure, signal_table
from simdiff.errors import SimdiffError


def test_paired_conditions_earth_plus_k_one_factor_seeded_by_clip_id() -> None:
    conds = paired_conditions("16_05", 6, seed=0)
    assert [c.index for c in conds] == list(range(7))
    assert conds[0].factor == "earth" and conds[0].env.as_tuple() == (-9.81, 0.0, 0.0)
    factors = [c.factor for c in conds[1:]]
    assert sorted(factors) == ["gravity"] * 2 + ["wind_x"] * 2 + ["wind_y"] * 2  # balanced
    for c in conds[1:]:
        g, wx, wy = c.env.as_tuple()
        if c.factor == "gravity":
            assert -20 <= g <= -1 and wx == wy == 0
        else:
            assert g == -9.81 and abs(wx) <= 10 and abs(wy) <= 10 and (wx == 0) != (wy == 0)
    assert paired_conditions("16_05", 6, seed=0) == conds  # deterministic
    assert paired_conditions("16_06", 6, seed=0) != conds  # per clip
    assert paired_conditions("16_05", 6, seed=1) != conds  # per seed
    with pytest.raises(SimdiffError, match="conditions"):
        paired_conditions("16_05", 0)


def test_paired_conditions_narrowed_to_weak_gravity_keep_the_default_draw() -> None:
    default = paired_conditions("16_05", 6, seed=0)
    assert paired_conditions("16_05", 6, 0, ("gravity", "wind_x", "wind_y"), (-20.0, -1.0)) == default
    weak = paired_conditions("16_05", 8, 0, factors=("gravity",), gravity_range=(-5.0, -1.0))
    assert [c.factor for c in weak] == ["earth"] + ["gravity"] * 8
    gs = [c.env.as_tuple()[0] for c in weak[1:]]
    assert all(-5.0 <= g <= -1.0 for g in gs) and len(set(gs)) == 8
    assert all(c.env.as_tuple()[1:] == (0.0, 0.0) for c in weak)
    winds = paired_conditions("16_05", 4, 0, factors=("wind_y", "wind_x"))
    assert sorted(c.factor for c in winds[1:]) == ["wind_x", "wind_x", "wind_y", "wind_y"]
    with pytest.raises(SimdiffError, match="'drag'"):
        paired_conditions("16_05", 2, factors=("drag",))
    with pytest.raises(SimdiffError, match="-0.5"):
        paired_conditions("16_05", 2, gravity_range=(-5.0, -0.5))
    with pytest.raises(SimdiffError, match="gravity-range -1 -5"):
        paired_conditions("16_05", 2, gravity_range=(-1.0, -5.0))


def test_paired_conditions_at_one_gravity() -> None:
    """LO == HI: every gravity draw is that value (e.g. val replays at g -1.6); more draws than factors would
    simulate a clip twice under the same gravity, which is a one-line error naming the value."""
    moon = paired_conditions("16_05", 1, 0, factors=("gravity",), gravity_range=(-1.6, -1.6))
    assert [(c.factor, c.env.as_tuple()) for c in moon] == [("earth", (-9.81, 0.0, 0.0)), ("gravity", (-1.6, 0.0, 0.0))]
    three = paired_conditions("16_05", 3, 0, gravity_range=(-1.6, -1.6))
    assert [c.env.as_tuple()[0] for c in three if c.factor == "gravity"] == [-1.6]
    with pytest.raises(SimdiffError, match=r"gravity-range -1.6 -1.6 is one gravity: with --conditions 2 over 1"):
        paired_conditions("16_05", 2, 0, factors=("gravity",), gravity_range=(-1.6, -1.6))
    from simdiff.data.augment import AugmentConfig

    with pytest.raises(SimdiffError, match="is one gravity"):  # the run's config refuses it before writing anything
        AugmentConfig(mode="paired", conditions=2, factors=("gravity",), gravity_range=(-1.6, -1.6))
    assert AugmentConfig(mode="paired", conditions=1, factors=("gravity",), gravity_range=(-1.6, -1.6)).gravity_range \
        == (-1.6, -1.6)


def test_augment_cli_narrows_the_draw_and_refuses_it_outside_paired_mode(tmp_path: Path, capsys) -> None:
    import json

    from simdiff.cli.main import main
    from simdiff.data.augment import AugmentConfig, augment
    from simdiff.eval.testing import write_tiny_corpus

    from test_augment import FakeProjector

    corpus = write_tiny_corpus(tmp_path / "src", n_train=2, n_test=1)
    config = AugmentConfig(mode="paired", conditions=2, factors=("gravity",), gravity_range=(-3.0, -1.0))
    report = augment(corpus, tmp_path / "aug", config, projector=FakeProjector(), progress=False)
    assert report["settings"]["factors"] == ["gravity"] and report["settings"]["gravity_range"] == [-3.0, -1.0]
    for row in json.loads((tmp_path / "aug" / "env.json").read_text()).values():
        assert row["env"][0] == -9.81 or -3.0 <= row["env"][0] <= -1.0
    with pytest.raises(SimdiffError, match="mode 'binary'"):
        augment(corpus, tmp_path / "b", AugmentConfig(mode="binary", factors=("gravity",)), projector=FakeProjector(),
                progress=False)
    assert main(["data", "augment", "--corpus", str(corpus), "--out", str(tmp_path / "c"),
                 "--gravity-range", "-3", "0.5"]) != 0
    assert "argument --gravity-range: 0.5 is outside [-100, -0.1]" in capsys.readouterr().err


def test_paired_draws_are_uncorrelated_with_content_but_round_robin_is_not() -> None:
    """Content that repeats with the round-robin cycle (30 conditions, 2 per clip: 15 clips), so
    that each condition always meets the same kind of clip: paired passes,
    round-robin fails."""
    from simdiff.data.augment.conditions import random_conditions
    from simdiff.data.augment.run import assign_conditions

    clips = [f"{k // 20:02d}_{k:03d}" for k in range(400)]
    speed = {c: float(k % 15) / 10 for k, c in enumerate(clips)}
    content = {c: {"speed": speed[c], "flight_total_s": 0.0, "flight_s": 0.0} for c in clips}
    pairs = [{"clip": c, "env": list(e.env.as_tuple())} for c in clips for e in paired_conditions(c, 6)]
    check = confound_check(pairs, content, bound=0.1)
    assert check["passes"], check["worst"]
    conds = random_conditions(30, seed=0)
    rr = assign_conditions(clips, conds, 2)
    pairs = [{"clip": c, "env": list(e.env.as_tuple())} for c in clips for e in rr[c]]
    check = confound_check(pairs, content, bound=0.1)
    assert not check["passes"] and check["max_abs_r"] > 0.2


def test_confound_check_finds_a_planted_correlation() -> None:
    rng = np.random.default_rng(0)
    clips = [f"c_{i}" for i in range(300)]
    content = {c: {"speed": float(rng.uniform(0, 2)), "flight_total_s": 0.0} for c in clips}
    pairs = [{"clip": c, "env": [-9.81 - 3 * content[c]["speed"], 0.0, 0.0]} for c in clips]
    check = confound_check(pairs, content)
    assert check["r"]["g_z"]["speed"] == pytest.approx(-1.0)
    assert check["worst"] == ["g_z", "speed"] and check["passes"] is False
    assert motion_type({"flight_s": 0.3, "speed": 0.0}) == "flight"
    assert motion_type({"flight_s": 0.0, "speed": 1.0}) == "locomotion"
    assert motion_type({}) == "static"


def _ballistic_hop(g: float, v: float = 1.5, fps: float = 20.0, stand: int = 10) -> np.ndarray:
    """A rigid standing body that hops once with take-off speed v under g, drifting +X at 0.1 m/s."""
    t_air = 2 * v / abs(g)
    n_air = int(round(t_air * fps))
    T = 2 * stand + n_air
    j = np.zeros((T, 22, 3))
    j[:, :, 1] = np.linspace(0.0, 0.9, 22)  # joints stacked from the floor up
    j[:, [7, 8], 1] = 0.08
    j[:, [10, 11], 1] = 0.02
    tt = (np.arange(n_air) + 0.5) / fps
    j[stand : stand + n_air, :, 1] += (v * tt - 0.5 * abs(g) * tt**2)[:, None]
    j[:, :, 0] += 0.1 * np.arange(T)[:, None] / fps
    return j


def test_measure_reads_flight_time_apex_and_drift() -> None:
    m_earth, m_moon = measure(_ballistic_hop(-9.81)), measure(_ballistic_hop(-1.6))
    assert m_earth["flights"] == 1 and m_moon["flights"] == 1
    assert m_moon["flight_s"] / m_earth["flight_s"] == pytest.approx(9.81 / 1.6, rel=0.2)
    assert m_moon["apex_gain_m"] == pytest.approx(1.5**2 / (2 * 1.6), rel=0.1)
    assert m_moon["drift_x"] == pytest.approx(0.1 * m_moon["duration_s"], rel=0.05)
    with pytest.raises(SimdiffError, match="shape"):
        measure(np.zeros((5, 21, 3)))


def test_signal_table_against_the_clips_own_earth_rollout() -> None:
    earth, moon = measure(_ballistic_hop(-9.81)), measure(_ballistic_hop(-1.6))
    windy = dict(earth, drift_x=earth["drift_x"] + 0.05)
    records = [
        {"clip": "a", "env": [-9.81, 0, 0], "kept": True, "signal": earth},
        {"clip": "a", "env": [-1.6, 0, 0], "kept": True, "signal": moon},
        {"clip": "a", "env": [-9.81, 5.0, 0], "kept": True, "signal": windy},
        {"clip": "a", "env": [-9.81, 0, -8.0], "kept": False, "signal": None},
    ]
    table = signal_table(records)
    lo = table[condition_bin([-1.6, 0, 0])]
    assert lo["kept"] == 1 and lo["flight_ratio"] == pytest.approx(moon["flight_s"] / earth["flight_s"])
    assert lo["d_apex_m"] > 0.4
    wind = table[condition_bin([-9.81, 5.0, 0])]
    assert wind["drift_per_10n_m"] == pytest.approx(0.1)  # 5 cm at 5 N → 10 cm per 10 N
    assert table[condition_bin([-9.81, 0, -8.0])]["keep_rate"] == 0.0
    assert condition_bin([-9.81, 0, 0]) == "earth" and condition_bin([-1.6, 0, 0]) == "g[-3,-1)"


def test_paired_augment_run_writes_report_with_bins_confound_and_signal(tmp_path: Path) -> None:
    from simdiff.data.augment import AugmentConfig, augment
    from simdiff.eval.testing import write_tiny_corpus

    from test_augment import FakeProjector

    corpus = write_tiny_corpus(tmp_path / "src", n_train=4, n_test=2)
    out = tmp_path / "aug"
    report = augment(corpus, out, AugmentConfig(mode="paired", conditions=3, shard_size=2), projector=FakeProjector(),
                     progress=False)
    assert report["pairs"] == 4 * 4 and report["settings"]["conditions"] == 3
    assert "earth" in report["per_bin"] and report["per_bin"]["earth"]["pairs"] == 4
    assert report["confound"]["pairs"] == report["kept"]
    assert "earth" in report["signal"]
    assert "Confound check" in (out / "report.md").read_text()
    import json

    env = json.loads((out / "env.json").read_text())
    assert len(env) == report["kept"]
    for row in env.values():  # every kept pair carries its own φ
        assert row["env"] in [list(c.env.as_tuple()) for c in paired_conditions(row["source"], 3)]
