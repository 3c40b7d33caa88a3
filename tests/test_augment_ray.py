"""The Ray backend of the augmentation driver gives the serial backend's result (needs the ``cluster`` extra)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from simdiff.data.augment import AugmentConfig, FilterConfig, augment
from simdiff.eval.testing import write_tiny_corpus


def _records(out: Path) -> list[dict]:
    timing = {"cpu_s", "sim_cpu_s"}
    recs = [r for p in sorted((out / "shards").glob("*.json")) for r in json.loads(p.read_text())["records"]]
    return [{**r, "info": {k: v for k, v in r["info"].items() if k not in timing}} for r in recs]


@pytest.mark.slow
def test_ray_backend_matches_serial(tmp_path: Path) -> None:
    ray = pytest.importorskip("ray")
    corpus = write_tiny_corpus(tmp_path / "c", n_train=4, n_test=1, frames=40)
    outs = {}
    try:
        for backend, workers in (("serial", 1), ("ray", 2)):
            outs[backend] = tmp_path / backend
            config = AugmentConfig(mode="paired", conditions=1, shard_size=2, workers=workers, backend=backend,
                                   filter=FilterConfig(max_pose_d_l2=1e9, max_residual_n=1e9))
            augment(corpus, outs[backend], config, progress=False)
    finally:
        ray.shutdown()
    serial, parallel = _records(outs["serial"]), _records(outs["ray"])
    assert len(serial) == 8 and serial == parallel
    assert (outs["serial"] / "train.txt").read_text() == (outs["ray"] / "train.txt").read_text()
