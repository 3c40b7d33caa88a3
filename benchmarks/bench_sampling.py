"""Sampling time per motion: DDPM-1000 vs DDIM-50, batched vs unbatched CFG, ``mdm`` and ``small`` sizes.

Usage::

    python benchmarks/bench_sampling.py [--device cpu] [--sizes mdm small] [--batch 1 8]
        [--frames 196] [--probe-steps 10] [--repeats 3] [--full] [--json out.json]

Random weights (speed does not depend on them). The text is pre-encoded, so the numbers are
the denoiser loop only. By default each configuration runs ``--probe-steps`` real sampler
steps after a warm-up and scales the per-step time to the full 1000 / 50 steps (the loop cost
is linear in steps); ``--full`` runs the complete loops instead.
"""

from __future__ import annotations

import argparse
import json
import platform
import time

import torch

from simdiff.diffusion.config import SamplingConfig
from simdiff.diffusion.sampling import make_scheduler, sample
from simdiff.model import Condition, MDMBackbone, backbone_preset


def _sync(device: torch.device) -> None:
    if device.type == "cuda":
        torch.cuda.synchronize(device)


def time_sampling(net: MDMBackbone, sampler: str, steps: int, batch: int, frames: int, batched_cfg: bool,
                  device: torch.device, probe: int | None, repeats: int = 1) -> float:
    """Seconds for one full sampling loop of ``batch`` motions.

    Extrapolated from ``probe`` steps when given; the best of ``repeats`` runs (a shared machine's
    other load only ever adds time).
    """
    total = len(make_scheduler(sampler, steps).timesteps)
    run_steps = total if probe is None else min(probe, total)  # every step costs one network pass
    cond = Condition(text=torch.randn(batch, net.config.text_dim, device=device))
    gen = torch.Generator(device=device).manual_seed(0)
    sample(net, SamplingConfig(sampler=sampler, steps=2), cond, frames, generator=gen, batched_cfg=batched_cfg)  # warm-up
    best = float("inf")
    for _ in range(repeats):
        _sync(device)
        start = time.perf_counter()
        sample(net, SamplingConfig(sampler=sampler, steps=run_steps), cond, frames, generator=gen,
               batched_cfg=batched_cfg)
        _sync(device)
        best = min(best, time.perf_counter() - start)
    return best * total / run_steps


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--device", default="cpu")
    parser.add_argument("--sizes", nargs="+", default=["mdm", "small"])
    parser.add_argument("--batch", type=int, nargs="+", default=[1, 8])
    parser.add_argument("--frames", type=int, default=196)
    parser.add_argument("--probe-steps", type=int, default=10)
    parser.add_argument("--full", action="store_true", help="run complete loops (slow on CPU)")
    parser.add_argument("--repeats", type=int, default=3, help="best of this many timed runs")
    parser.add_argument("--threads", type=int, default=0, help="torch intra-op threads (0: leave as is)")
    parser.add_argument("--json", help="also write the results here")
    args = parser.parse_args()
    if args.threads:
        torch.set_num_threads(args.threads)
    device = torch.device(args.device)
    rows = []
    print(f"device={device} threads={torch.get_num_threads()} frames={args.frames} "
          f"({'full loops' if args.full else f'extrapolated from {args.probe_steps} steps'})")
    print(f"{'size':6} {'sampler':9} {'B':>3} {'cfg':9} {'s/motion':>9} {'s/batch':>9}")
    for size in args.sizes:
        torch.manual_seed(0)
        net = MDMBackbone(backbone_preset(size, text_dim=512 if size == "mdm" else 384)).to(device).eval()
        for sampler, steps in (("ddpm", 1000), ("ddim", 50)):
            for batch in args.batch:
                for batched in (True, False):
                    seconds = time_sampling(net, sampler, steps, batch, args.frames, batched, device,
                                            None if args.full else args.probe_steps, args.repeats)
                    row = dict(size=size, sampler=f"{sampler}-{steps}", batch=batch,
                               cfg="batched" if batched else "unbatched", seconds_per_batch=seconds,
                               seconds_per_motion=seconds / batch)
                    rows.append(row)
                    print(f"{size:6} {row['sampler']:9} {batch:>3} {row['cfg']:9} {seconds / batch:9.3f} {seconds:9.3f}", flush=True)
    if args.json:
        meta = dict(device=str(device), threads=torch.get_num_threads(), torch=torch.__version__,
                    cpu=platform.processor() or platform.machine(), frames=args.frames, full=args.full,
                    probe_steps=None if args.full else args.probe_steps, repeats=args.repeats)
        with open(args.json, "w") as f:
            json.dump(dict(meta=meta, rows=rows), f, indent=2)


if __name__ == "__main__":
    main()
