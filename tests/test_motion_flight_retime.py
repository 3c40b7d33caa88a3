"""Flights re-timed to another gravity (simdiff/motion/flight_retime.py) and the reduced-gravity folder made from them
(simdiff/data/augment/kinematic.py, ``simdiff data reduced-gravity``)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from simdiff.cli.main import main
from simdiff.data.augment.dataset import read_env_table
from simdiff.data.augment.kinematic import KinematicConfig, draw_gravity, make_reduced_gravity, transform
from simdiff.data.clip_files import process_clip, write_clip
from simdiff.errors import SimdiffError
from simdiff.motion.flight_retime import retime_flights
from simdiff.motion.gait import gait_measures
from simdiff.motion.gravity_readout import flight_fits, read_gravity
from simdiff.motion.synthetic import jump, walk


def earth_jump() -> np.ndarray:
    airtime = float(np.sqrt(8 * 0.4 / 9.81))  # a 0.4 m pelvis rise at Earth's gravity
    return jump(frames=70, height=0.4, start=20, airtime=airtime)


def bones(joints: np.ndarray) -> np.ndarray:
    from simdiff.motion.skeleton import PARENTS

    return np.stack([np.linalg.norm(joints[:, i] - joints[:, p], axis=-1) for i, p in enumerate(PARENTS) if p >= 0], 1)


@pytest.mark.parametrize("gravity", [-1.6, -3.7, -9.81, -20.0])
def test_a_retimed_flight_reads_the_new_gravity_and_keeps_its_take_off(gravity: float) -> None:
    source = earth_jump()
    out = retime_flights(source, gravity)
    (before,), (after,) = flight_fits(source), flight_fits(out)
    assert after.gravity == pytest.approx(gravity, rel=1e-3) and after.rmse_m < 1e-4
    assert after.start == before.start
    np.testing.assert_allclose(out[: before.start], source[: before.start], atol=1e-6)  # stance unchanged
    # same take-off speed: apex and airborne time scale with 1/|g| (the fitted frames start a little after take-off)
    source_g = before.gravity
    assert after.apex_m == pytest.approx(before.apex_m * source_g / gravity, rel=0.15 if gravity > -9 else 0.3)
    assert (after.end - after.start > before.end - before.start) == (gravity > source_g)
    if gravity >= -9.81:  # weaker gravity: no jump at the seams (a stronger one lands harder)
        assert np.abs(np.diff(out, axis=0)).max() <= np.abs(np.diff(source, axis=0)).max() * 1.05
    np.testing.assert_allclose(bones(out), np.broadcast_to(bones(source)[:1], bones(out).shape), atol=2e-3)
    np.testing.assert_allclose(out[-1, :, 1], source[-1, :, 1], atol=1e-5)  # lands on the same floor


def test_no_flight_is_unchanged_and_bad_gravity_is_one_line() -> None:
    still = walk(40, speed=1.0)
    np.testing.assert_allclose(retime_flights(still, -1.6), still, atol=1e-6)
    for bad in (0.0, 3.0, float("nan")):
        with pytest.raises(SimdiffError, match="gravity must be a negative"):
            retime_flights(earth_jump(), bad)
    with pytest.raises(SimdiffError, match="would last"):
        retime_flights(jump(frames=70, height=0.6, start=20, airtime=0.7), -0.05)


def test_walks_are_slowed_to_the_same_froude_number_and_other_types_have_no_rule() -> None:
    source = walk(60, speed=1.2, stride_hz=1.0)
    slow = transform(source, "walk", -1.6)
    ratio = gait_measures(slow)["pelvis_speed"] / gait_measures(source)["pelvis_speed"]
    assert ratio == pytest.approx(np.sqrt(1.6 / 9.81), rel=0.03)  # 0.40x: v ∝ √g at a fixed Froude number
    assert transform(source, "gesture", -1.6) is None
    assert transform(walk(60, speed=0.0), "jump", -1.6) is None  # a "jump" without a free flight is left out


def _corpus(root: Path) -> Path:
    rows = [("jump_a", "jump", earth_jump(), "a person jumps."), ("walk_a", "walk", walk(50, speed=1.2), "a person walks."),
            ("wave_a", "gesture", walk(50, speed=0.0), "a person waves.")]
    clips = []
    for cid, kind, joints, caption in rows:
        features, recovered = process_clip(cid, joints)
        write_clip(root, cid, features, recovered, [f"{caption}#a/DET#0.0#0.0"])
        clips.append({"id": cid, "split": "train", "motion_type": kind, "frames": len(features), "captions": [caption],
                      "licence": "CMU", "source": "cmu-amc", "mirror_of": None})
    (root / "manifest.json").write_text(json.dumps({"clips": clips}))
    (root / "train.txt").write_text("".join(f"{c['id']}\n" for c in clips))
    np.save(root / "Mean.npy", np.zeros(263, np.float32))
    np.save(root / "Std.npy", np.ones(263, np.float32))
    return root


def test_the_folder_has_an_earth_item_and_drawn_gravities_per_clip(tmp_path: Path) -> None:
    corpus = _corpus(tmp_path / "corpus")
    config = KinematicConfig(conditions=3, gravity_range=(-4.0, -1.5), seed=5)
    summary = make_reduced_gravity(corpus, tmp_path / "out", config, progress=False)
    assert summary["items"] == 8 and summary["sources"] == 2  # the gesture has no rule
    table = read_env_table(tmp_path / "out")
    assert sorted(table) == (tmp_path / "out" / "train.txt").read_text().split()
    jumps = {k: v for k, v in table.items() if v["source"] == "jump_a"}
    assert [v["env"][0] for _, v in sorted(jumps.items())] == [-9.81, *draw_gravity("jump_a", config)]
    assert all(-4.0 <= g <= -1.5 for g in draw_gravity("jump_a", config))
    for item, row in jumps.items():
        joints = np.load(tmp_path / "out" / "new_joints" / f"{item}.npy")
        assert read_gravity(joints)["gravity"] == pytest.approx(row["env"][0], rel=0.02)  # through the features
        assert (tmp_path / "out" / "texts" / f"{item}.txt").read_text().startswith("a person jumps.")
    assert draw_gravity("jump_a", config) == draw_gravity("jump_a", KinematicConfig(conditions=3, gravity_range=(-4.0, -1.5), seed=5))
    assert draw_gravity("jump_a", config) != draw_gravity("walk_a", config)


def test_cli_writes_the_folder_and_bad_input_is_one_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    corpus = _corpus(tmp_path / "corpus")
    assert main(["data", "reduced-gravity", "--corpus", str(corpus), "--out", str(tmp_path / "o"), "--conditions", "1",
                 "--no-progress"]) == 0
    assert "4 items from 2 clips" in capsys.readouterr().out
    assert main(["data", "reduced-gravity", "--corpus", str(corpus), "--out", str(tmp_path / "p"),
                 "--gravity-range", "-3", "0.5"]) == 2
    err = capsys.readouterr().err
    assert "0.5 is outside" in err and err.count("\n") == 1 and not (tmp_path / "p").exists()
    with pytest.raises(SimdiffError, match="gravity range must be"):
        KinematicConfig(gravity_range=(-1.0, -3.0))


def test_an_interrupted_run_leaves_no_folder(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    import simdiff.data.augment.kinematic as kinematic

    corpus = _corpus(tmp_path / "corpus")
    calls = []

    def stop_after_two(*args):
        calls.append(args)
        if len(calls) > 2:
            raise KeyboardInterrupt
        return transform(*args)

    monkeypatch.setattr(kinematic, "transform", stop_after_two)
    with pytest.raises(KeyboardInterrupt):
        make_reduced_gravity(corpus, tmp_path / "new" / "out", KinematicConfig(conditions=1), progress=False)
    assert not (tmp_path / "new").exists()
    with pytest.raises(SimdiffError, match="not a corpus folder"):
        make_reduced_gravity(tmp_path / "nothing", tmp_path / "o", KinematicConfig(), progress=False)
