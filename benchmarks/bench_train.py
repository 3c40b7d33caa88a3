"""Training step time (forward + backward + AdamW) for the ``mdm`` and ``small`` backbones and adapters.

Usage::

    python benchmarks/bench_train.py [--device cpu] [--sizes mdm small] [--batch 64] [--frames 196]
        [--steps 3] [--json out.json]

Random data and pre-encoded text: this is the network + optimiser cost only.
"""

from __future__ import annotations

import argparse
import json
import time

import torch

from simdiff.diffusion.ddpm import DDPMScheduler
from simdiff.diffusion.losses import diffusion_loss
from simdiff.model import Condition, SimConfig, SimDiffNet, backbone_preset
from simdiff.model.backbone import MDMBackbone


def time_steps(net: torch.nn.Module, params: list[torch.nn.Parameter], batch: int, frames: int, steps: int,
               device: torch.device, env: bool) -> float:
    """Best (minimum) seconds per optimiser step after one warm-up step."""
    opt = torch.optim.AdamW(params, lr=1e-4)
    sched = DDPMScheduler()
    text_dim = (net.backbone if isinstance(net, SimDiffNet) else net).config.text_dim
    x0 = torch.randn(batch, frames, 263, device=device)
    mask = torch.ones(batch, frames, dtype=torch.bool, device=device)
    cond = Condition(text=torch.randn(batch, text_dim, device=device), uncond=torch.rand(batch, device=device) < 0.1,
                     frame_mask=mask, env=torch.randn(batch, 3, device=device) if env else None)
    net.train()
    times = []
    for i in range(steps + 1):
        if device.type == "cuda":
            torch.cuda.synchronize(device)
        start = time.perf_counter()
        loss = diffusion_loss(net, sched, x0, cond, mask)
        opt.zero_grad(set_to_none=True)
        loss.backward()
        opt.step()
        if device.type == "cuda":
            torch.cuda.synchronize(device)
        if i:
            times.append(time.perf_counter() - start)
    return min(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--device", default="cpu")
    parser.add_argument("--sizes", nargs="+", default=["mdm", "small"])
    parser.add_argument("--batch", type=int, default=64)
    parser.add_argument("--frames", type=int, default=196)
    parser.add_argument("--steps", type=int, default=3)
    parser.add_argument("--threads", type=int, default=0)
    parser.add_argument("--json")
    args = parser.parse_args()
    if args.threads:
        torch.set_num_threads(args.threads)
    device = torch.device(args.device)
    rows = []
    print(f"device={device} threads={torch.get_num_threads()} batch={args.batch} frames={args.frames}")
    for size in args.sizes:
        cfg = backbone_preset(size, text_dim=512 if size == "mdm" else 384)
        torch.manual_seed(0)
        backbone = MDMBackbone(cfg).to(device)
        t_bb = time_steps(backbone, list(backbone.parameters()), args.batch, args.frames, args.steps, device, env=False)
        simdiff = SimDiffNet(cfg, SimConfig()).to(device)
        simdiff.backbone.requires_grad_(False)
        t_ad = time_steps(simdiff, simdiff.adapter_parameters(), args.batch, args.frames, args.steps, device, env=True)
        for mode, seconds in (("backbone", t_bb), ("adapters", t_ad)):
            rows.append(dict(size=size, mode=mode, batch=args.batch, seconds_per_step=seconds))
            print(f"{size:6} {mode:9} {seconds:8.3f} s/step  ({args.batch / seconds:7.1f} clips/s)", flush=True)
    if args.json:
        with open(args.json, "w") as f:
            json.dump(dict(device=str(device), threads=torch.get_num_threads(), frames=args.frames, rows=rows), f, indent=2)


if __name__ == "__main__":
    main()
