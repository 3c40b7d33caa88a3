"""Shared test fixtures.

Real third-party data lives outside the project, in ``../shared/data`` beside the checkout
(or wherever ``SIMDIFF_SHARED_DATA`` points). Tests that need it use the ``shared_data``
fixture and skip cleanly when it is absent.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

REPO_ROOT = Path(__file__).resolve().parents[1]


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
