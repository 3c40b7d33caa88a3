"""``simdiff track`` and the projection pool."""

from __future__ import annotations

import json

import numpy as np
import pytest

pytest.importorskip("mujoco")

from simdiff.cli.main import main  # noqa: E402
from simdiff.sim import synthetic  # noqa: E402


@pytest.fixture(scope="module")
def motion_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("m") / "squat.npy"
    np.save(path, synthetic.squat(30))
    return path


def test_track_json_and_out(motion_file, tmp_path, capsys):
    rc = main(["track", str(motion_file), "--json", "--out", str(tmp_path)])
    assert rc == 0
    rec = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    for key in ("success", "fall_frame", "d_l2", "err_mm", "residual", "cpu_s"):
        assert key in rec
    assert rec["success"] is True
    out = np.load(tmp_path / "squat.npy")
    assert out.shape == (30, 22, 3) and out.dtype == np.float32


def test_track_text_strict(motion_file, capsys):
    assert main(["track", str(motion_file), "--residual", "0", "--gravity", "-9.81", "--wind", "0", "5"]) == 0
    text = capsys.readouterr().out
    assert "squat.npy" in text and "tracked" in text


@pytest.mark.parametrize("argv", [["--gravity", "-25"], ["--wind", "9", "9"], ["--residual", "-1"]])
def test_track_bad_phi(motion_file, capsys, argv):
    assert main(["track", str(motion_file), *argv]) == 2
    err = capsys.readouterr().err
    assert err.startswith("simdiff: error:") and len(err.strip().splitlines()) == 1


def test_track_workers_same_results(motion_file, tmp_path, capsys):
    """--workers 2 (spawned processes) gives the same rollouts and numbers as --workers 1, in order."""
    other = tmp_path / "standing.npy"
    np.save(other, synthetic.standing(20))
    files = [str(motion_file), str(other)]
    runs = []
    for workers in ("1", "2"):
        out = tmp_path / f"w{workers}"
        assert main(["track", *files, "--json", "--out", str(out), "--workers", workers]) == 0
        captured = capsys.readouterr()
        records = [json.loads(line) for line in captured.out.strip().splitlines()]
        assert "tracking" in captured.err  # the progress bar
        for r in records:  # timings and output paths differ between runs
            for key in ("cpu_s", "sim_cpu_s", "out"):
                r.pop(key)
        runs.append((records, [np.load(out / n) for n in ("squat.npy", "standing.npy")]))
    (rec1, arr1), (rec2, arr2) = runs
    assert [r["file"] for r in rec1] == files and rec1 == rec2
    for a, b in zip(arr1, arr2):
        np.testing.assert_array_equal(a, b)


def test_track_bad_workers(motion_file, capsys):
    assert main(["track", str(motion_file), "--workers", "-1"]) == 2
    assert "--workers" in capsys.readouterr().err


def test_track_missing_file(tmp_path, capsys):
    assert main(["track", str(tmp_path / "nope.npy")]) == 2


def test_pool_serial_and_process():
    from simdiff.sim.env import Environment
    from simdiff.sim.pool import PoolConfig, ProjectionPool

    motions = [synthetic.standing(12), synthetic.squat(12)]
    envs = [Environment(), Environment(-3.0)]
    serial = ProjectionPool(PoolConfig(backend="serial")).map(motions, envs)
    with ProjectionPool(PoolConfig(workers=2)) as pool:
        par = pool.map(motions, envs)
    for (a, ia), (b, ib) in zip(serial, par):
        assert ia.success == ib.success
        assert np.allclose(a, b)  # deterministic across processes
    bad = ProjectionPool(PoolConfig(backend="serial")).map([np.zeros((3, 22, 3))])
    assert bad[0][0] is None and "too short" in bad[0][1]
