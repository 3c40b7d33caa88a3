"""Two-process DDP training on CPU with gloo."""

from __future__ import annotations

import os
import socket
import pytest
import torch
import torch.multiprocessing as mp


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _worker(rank: int, world: int, port: int, out: str) -> None:
    import torch.distributed as dist

    from simdiff.train import Trainer, synthetic_dataset
    from simdiff.train.testing import HashTextEncoder as HashText
    from simdiff.train.testing import tiny_run_config as run_config

    torch.set_num_threads(1)
    os.environ.update(MASTER_ADDR="127.0.0.1", MASTER_PORT=str(port))
    dist.init_process_group("gloo", rank=rank, world_size=world)
    try:
        trainer = Trainer(out, run_config(6, batch_size=4, save_every=3), synthetic_dataset(8, 20, max_frames=20),
                          text_encoder=HashText(), rank=rank, world_size=world)
        losses = trainer.train(progress=False)
        torch.save({"losses": losses, "state": trainer.network.state_dict()}, f"{out}/rank{rank}.pt")
    finally:
        dist.destroy_process_group()


@pytest.mark.slow
def test_ddp_two_processes_gloo(tmp_path) -> None:
    mp.spawn(_worker, args=(2, _free_port(), str(tmp_path)), nprocs=2, join=True)
    r0 = torch.load(tmp_path / "rank0.pt", weights_only=True)
    r1 = torch.load(tmp_path / "rank1.pt", weights_only=True)
    assert len(r0["losses"]) == 6 and r0["losses"] != r1["losses"]  # different data shards
    for key, value in r0["state"].items():
        assert torch.equal(value, r1["state"][key]), key  # gradients were all-reduced
    assert (tmp_path / "checkpoints" / "step_000000006").is_dir() and (tmp_path / "model" / "model.safetensors").is_file()
