"""Stopping commands that run worker processes: Ctrl-C, SIGTERM and a killed worker end in one line, no traceback,
the right exit status, and a state on disk that the same command resumes to the uninterrupted result."""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

from simdiff.eval.testing import write_tiny_corpus

pytestmark = pytest.mark.skipif(not os.path.isdir("/proc/self"), reason="finds worker processes in /proc")

AUGMENT = ["--mode", "binary", "--workers", "2", "--shard-size", "1", "--no-progress"]
ENV = {**os.environ, "OMP_NUM_THREADS": "1", "PYTHONUNBUFFERED": "1"}


def _augment(corpus: Path, out: Path) -> subprocess.Popen[str]:
    return subprocess.Popen([sys.executable, "-m", "simdiff", "data", "augment", "--corpus", str(corpus), "--out",
                             str(out), *AUGMENT], env=ENV, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True)


def _workers(parent: int) -> list[int]:
    """Pool workers among ``parent``'s children (not multiprocessing's resource tracker)."""
    found = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            ppid = int((entry / "stat").read_text().rsplit(")", 1)[1].split()[1])
            cmdline = (entry / "cmdline").read_bytes()
        except (OSError, IndexError, ValueError):
            continue
        if ppid == parent and b"resource_tracker" not in cmdline:
            found.append(int(entry.name))
    return sorted(found)


def _wait_for(path: Path, proc: subprocess.Popen[str], timeout: float = 90.0) -> None:
    deadline = time.monotonic() + timeout
    while not path.exists() and time.monotonic() < deadline and proc.poll() is None:
        time.sleep(0.01)
    assert proc.poll() is None, f"finished before it could be stopped: {proc.communicate()}"
    assert path.exists()


BOOTSTRAP_NOISE = re.compile(r"Traceback \(most recent call last\):\n(?:  .*\n)*?(?:BrokenPipeError|EOFError)\b.*(?:\n|$)")


def _quiet(err: str) -> bool:
    """No traceback and at most 3 lines besides the progress bar's. A worker still in multiprocessing's spawn
    bootstrap when the pool stops can die on its closed pipe before our code runs in it; that traceback (frames in
    ``<string>`` or ``multiprocessing``, ending in BrokenPipeError/EOFError) is the interpreter's, not the command's."""
    for block in [m.group(0) for m in BOOTSTRAP_NOISE.finditer(err)]:
        if "multiprocessing" in block or '"<string>"' in block:
            err = err.replace(block, "")
    lines = [line for line in err.splitlines() if line.strip() and "%|" not in line]
    return "Traceback" not in err and len(lines) <= 3


def _tree(root: Path) -> dict[str, object]:
    """Every file of an augmented corpus but the report (timings); shard records without their CPU times."""
    def strip(value: object) -> object:
        if isinstance(value, dict):
            return {k: strip(v) for k, v in value.items() if not k.endswith("cpu_s")}
        if isinstance(value, list):
            return [strip(v) for v in value]
        return value

    tree: dict[str, object] = {}
    for path in sorted(root.rglob("*")):
        if path.is_file() and path.name not in ("report.json", "report.md"):
            key = str(path.relative_to(root))
            tree[key] = strip(json.loads(path.read_text())) if path.parent.name == "shards" else path.read_bytes()
    return tree


@pytest.fixture(scope="module")
def clean(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict[str, object]]:
    """A tiny corpus and its uninterrupted augmentation."""
    root = tmp_path_factory.mktemp("interrupt")
    corpus = write_tiny_corpus(root / "c", n_train=3, n_test=1, frames=48)
    proc = _augment(corpus, root / "clean")
    _, err = proc.communicate(timeout=300)
    assert proc.returncode == 0, err
    return corpus, _tree(root / "clean")


def _stop_and_resume(clean: tuple[Path, dict[str, object]], tmp_path: Path, how: str) -> tuple[int, str]:
    corpus, expected = clean
    out = tmp_path / "aug"
    proc = _augment(corpus, out)
    try:
        _wait_for(out / "shards" / "shard_00000.json", proc)
        if how == "ctrl-c":  # the terminal sends SIGINT to the whole foreground process group
            os.killpg(proc.pid, signal.SIGINT)
        elif how == "sigterm":  # a scheduler stops the command's own process
            proc.send_signal(signal.SIGTERM)
        else:
            workers = _workers(proc.pid)
            assert workers, "no worker process found"
            os.kill(workers[0], signal.SIGKILL)
        _, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
    resumed = _augment(corpus, out)
    _, resumed_err = resumed.communicate(timeout=300)
    assert resumed.returncode == 0, resumed_err
    assert _tree(out) == expected
    assert _quiet(err), err
    return proc.returncode, err


def test_ctrl_c_stops_workers_quietly_and_the_rerun_resumes(clean, tmp_path: Path) -> None:
    code, err = _stop_and_resume(clean, tmp_path, "ctrl-c")
    assert code == 130, err
    assert "interrupted" in err and "of 3 clips done" in err and "run the same command again" in err


def test_sigterm_stops_workers_quietly_and_the_rerun_resumes(clean, tmp_path: Path) -> None:
    code, err = _stop_and_resume(clean, tmp_path, "sigterm")
    assert code == 143, err
    assert "SIGTERM" in err and "of 3 clips done" in err


def test_a_killed_worker_is_one_line_and_the_rerun_resumes(clean, tmp_path: Path) -> None:
    code, err = _stop_and_resume(clean, tmp_path, "kill-worker")
    assert code == 1, err
    assert "a worker process died" in err and "run the same command again" in err  # its signal when still known


def _motions(tmp_path: Path, n: int) -> list[Path]:
    import numpy as np

    corpus = write_tiny_corpus(tmp_path / "c", n_train=2, n_test=1, frames=48)
    joints = np.load(corpus / "new_joints" / "000000.npy")
    paths = []
    for k in range(n):
        path = tmp_path / f"m{k}.npy"
        np.save(path, joints)
        paths.append(path)
    return paths


@pytest.mark.parametrize("how", ["ctrl-c", "kill-worker"])
def test_track_stops_quietly(tmp_path: Path, how: str) -> None:
    files = [str(p) for p in _motions(tmp_path, 8)]
    proc = subprocess.Popen([sys.executable, "-m", "simdiff", "track", *files, "--workers", "2"], env=ENV,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True)
    try:
        assert proc.stdout is not None
        first = proc.stdout.readline()  # the first motion is reported: the workers are busy with the next
        assert first.startswith("m0.npy"), first
        if how == "ctrl-c":
            os.killpg(proc.pid, signal.SIGINT)
        else:
            os.kill(_workers(proc.pid)[0], signal.SIGKILL)
        _, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
    assert _quiet(err), err
    if how == "ctrl-c":
        assert proc.returncode == 130 and "interrupted" in err and "of 8 motions done" in err, err
    else:
        assert proc.returncode == 1 and "a worker process died" in err, err


BUILD = textwrap.dedent('''
    import sys, time
    from pathlib import Path
    import simdiff.data.corpus.build as build
    from simdiff.sim.pool import WorkerDied, stop_signals, stopped

    def slow(item, settings):
        if item == "first":
            return [], None, True
        open({marker!r}, "w").close()
        time.sleep(600)

    build._run_item = slow
    done = []
    try:
        with stop_signals():
            build._run_pool([("first", "k")] + [("item%d" % i, "k") for i in range(5)], None, 2,
                            lambda item, key, result: done.append(item))
    except (KeyboardInterrupt, WorkerDied) as exc:
        sys.exit(stopped(exc))
''')


@pytest.mark.parametrize("how", ["ctrl-c", "sigterm", "kill-worker"])
def test_data_build_pool_stops_quietly(tmp_path: Path, how: str) -> None:
    marker = tmp_path / "busy"
    script = tmp_path / "build.py"
    script.write_text(BUILD.format(marker=str(marker)))
    proc = subprocess.Popen([sys.executable, str(script)], env=ENV, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, start_new_session=True)
    try:
        _wait_for(marker, proc, timeout=60)
        if how == "ctrl-c":
            os.killpg(proc.pid, signal.SIGINT)
        elif how == "sigterm":
            proc.send_signal(signal.SIGTERM)
        else:
            os.kill(_workers(proc.pid)[0], signal.SIGKILL)
        _, err = proc.communicate(timeout=30)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
    assert _quiet(err), err
    assert proc.returncode == {"ctrl-c": 130, "sigterm": 143, "kill-worker": 1}[how], err
    deadline = time.monotonic() + 10
    while _workers(proc.pid) and time.monotonic() < deadline:
        time.sleep(0.1)


def _exit_code(main, argv: list[str]) -> object:
    try:
        return main(argv)
    except SystemExit as exc:  # argparse's exit, when the entry point lets it through
        return exc.code


BAD_OPTIONS = [
    ("data augment", "--workers", "65"), ("data augment", "--workers", "-1"), ("data augment", "--seed", "nan"),
    ("data augment", "--seed", "-1"), ("data augment", "--conditions", "0"), ("data augment", "--conditions", "1000"),
    ("data augment", "--shard-size", "0"), ("data augment", "--shard-size", "99999999"),
    ("data augment", "--limit", "0"), ("data augment", "--per-clip", "nan"), ("data augment", "--earth-keep", "0"),
    ("data augment", "--earth-keep", "nan"), ("data augment", "--max-residual-n", "inf"),
    ("data augment", "--max-d-l2", "-1"), ("data augment", "--max-residual", "nan"),
    ("data augment", "--residual-bound", "inf"), ("data augment", "--resimulate-gravity-below", "inf"),
    ("data augment", "--max-pose-d-l2", "nan"), ("data augment", "--max-pose-d-l2", "1e10"),
    ("track", "--fps", "0"), ("track", "--fps", "-5"), ("track", "--fps", "nan"), ("track", "--fps", "inf"),
    ("track", "--fps", "2000"), ("track", "--workers", "65"), ("track", "--residual", "nan"),
    ("track", "--residual", "100"),
    ("data build", "--workers", "65"), ("data build", "--captions", "1"), ("data build", "--captions", "11"),
    ("data build", "--seed", "nan"),
]


@pytest.mark.parametrize("command, option, value", BAD_OPTIONS)
def test_numeric_options_are_checked_before_work(tmp_path: Path, capsys: pytest.CaptureFixture[str], command: str,
                                                 option: str, value: str) -> None:
    from simdiff.cli.main import main

    required = {"data augment": ["--corpus", str(tmp_path), "--out", str(tmp_path / "o")],
                "track": [str(tmp_path / "m.npy")],
                "data build": ["--shared", str(tmp_path), "--out", str(tmp_path / "o")]}[command]
    assert _exit_code(main, [*command.split(), *required, f"{option}={value}"]) == 2
    err = capsys.readouterr().err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and option in lines[0] and value in lines[0], err
    assert not (tmp_path / "o").exists()


def test_gravity_range_option_refuses_nan(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from simdiff.cli.main import main

    args = ["data", "augment", "--corpus", str(tmp_path), "--out", str(tmp_path / "o"), "--gravity-range", "nan", "-1"]
    assert _exit_code(main, args) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "--gravity-range" in err and "nan" in err, err


def test_library_worker_counts_are_bounded(tmp_path: Path) -> None:
    from simdiff.data.corpus.build import CorpusConfig, build
    from simdiff.errors import SimdiffError
    from simdiff.sim.pool import MAX_WORKERS, PoolConfig, ProjectionPool

    with pytest.raises(SimdiffError, match="workers"):
        ProjectionPool(PoolConfig(workers=MAX_WORKERS + 1))
    with pytest.raises(SimdiffError, match="workers"):
        ProjectionPool(PoolConfig(workers=-1))
    with pytest.raises(SimdiffError, match="--workers"):
        build(CorpusConfig(shared=tmp_path, out=tmp_path / "o", workers=MAX_WORKERS + 1, progress=False))
    with pytest.raises(SimdiffError, match="--captions"):
        build(CorpusConfig(shared=tmp_path, out=tmp_path / "o", captions=1000, progress=False))
