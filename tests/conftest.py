"""Shared test fixtures.

Real third-party data lives outside the project, in ``../shared/data`` beside the checkout
(or wherever ``SIMDIFF_SHARED_DATA`` points). Tests that need it use the ``shared_data``
fixture and skip cleanly when it is absent.

The tests run in a temporary working folder (MuJoCo writes ``MUJOCO_LOG.TXT`` into the working folder on
warnings), and a run that leaves a new file in the checkout, ignored or not, fails naming it.
"""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import pytest

REPO_ROOT = Path(__file__).resolve().parents[1]

LEFTOVER_EXEMPT: tuple[str, ...] = ("__pycache__/", ".pyc", ".pytest_cache/", ".egg-info/")
"""Byproducts of importing and installing, not of what a test does."""
_BEFORE = pytest.StashKey["set[str] | None"]()


def checkout_files() -> set[str] | None:
    """Untracked and ignored paths of the checkout as ``git status`` lists them (None: no git checkout)."""
    if shutil.which("git") is None or not (REPO_ROOT / ".git").exists():
        return None
    out = subprocess.run(["git", "status", "--porcelain", "--ignored"], cwd=REPO_ROOT, capture_output=True,
                         text=True, check=False)
    if out.returncode != 0:
        return None
    return {line[3:] for line in out.stdout.splitlines() if line[:2] in ("??", "!!")}


def pytest_sessionstart(session: pytest.Session) -> None:
    session.config.stash[_BEFORE] = checkout_files()


def pytest_sessionfinish(session: pytest.Session, exitstatus: int) -> None:
    before = session.config.stash.get(_BEFORE, None)
    after = checkout_files()
    if before is None or after is None:
        return
    left = sorted(p for p in after - before if not any(mark in p for mark in LEFTOVER_EXEMPT))
    if left:
        reporter = session.config.pluginmanager.get_plugin("terminalreporter")
        if reporter is not None:
            reporter.write_line("the tests left files in the checkout: " + ", ".join(left), red=True)
        session.exitstatus = pytest.ExitCode.TESTS_FAILED



@pytest.fixture(scope="session", autouse=True)
def _outside_the_checkout(tmp_path_factory: pytest.TempPathFactory):
    """Run every test in a fresh temporary working folder, so that files written to the working folder
    (MuJoCo's ``MUJOCO_LOG.TXT``) land outside the checkout."""
    cwd = os.getcwd()
    os.chdir(tmp_path_factory.mktemp("cwd"))
    yield
    os.chdir(cwd)


def shared_data_dir() -> Path | None:
    """The shared data folder, or None when this checkout has none."""
    env = os.environ.get("SIMDIFF_SHARED_DATA")
    path = Path(env) if env else REPO_ROOT.parent / "shared" / "data"
    return path if path.is_dir() else None


@pytest.fixture(scope="session")
def shared_data() -> Path:
    """Path to ``../shared/data``; skips the test when it is absent."""
    path = shared_data_dir()
    if path is None:
        pytest.skip("../shared/data is absent (set SIMDIFF_SHARED_DATA to its path)")
    return path


@pytest.fixture
def one_torch_thread():
    """One intra-op torch thread for the test: the test machine's 2 cores are shared, and one
    thread is faster and steadier there. Use with ``pytestmark = pytest.mark.usefixtures(...)``."""
    import torch

    threads = torch.get_num_threads()
    torch.set_num_threads(1)
    yield
    torch.set_num_threads(threads)


@pytest.fixture(scope="module")
def tiny_corpus(tmp_path_factory) -> Path:
    """A tiny HumanML3D-layout corpus (8 train, 4 val, 4 test clips of 48 frames), once per module."""
    from simdiff.eval.testing import write_tiny_corpus

    return write_tiny_corpus(tmp_path_factory.mktemp("corpus"), n_train=8, n_val=4, n_test=4, frames=48)
