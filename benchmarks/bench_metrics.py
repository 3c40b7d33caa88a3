"""Time ``physics_metrics`` on a batch of 1,000 motions x 196 frames x 22 joints.

Run: ``python benchmarks/bench_metrics.py [--batch 1000] [--frames 196] [--repeats 5]``.
Prints the best wall-clock time in seconds.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from simdiff.motion.metrics import physics_metrics


def make_batch(batch: int, frames: int, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Random walking-ish joints (batch, frames, 22, 3) float32 near the ground, and lengths."""
    rng = np.random.default_rng(seed)
    joints = rng.normal(0.0, 0.3, size=(batch, frames, 22, 3)).astype(np.float32)
    joints[..., 1] = np.abs(joints[..., 1]) - 0.01
    joints += np.cumsum(rng.normal(0.0, 0.01, size=(batch, frames, 1, 3)), axis=1).astype(np.float32)
    lengths = rng.integers(40, frames + 1, size=batch)
    return joints, lengths


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--batch", type=int, default=1000)
    parser.add_argument("--frames", type=int, default=196)
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    joints, lengths = make_batch(args.batch, args.frames)
    physics_metrics(joints[:2], lengths[:2])  # warm-up
    best = float("inf")
    for _ in range(args.repeats):
        start = time.perf_counter()
        result = physics_metrics(joints, lengths)
        best = min(best, time.perf_counter() - start)
    print(f"physics_metrics {args.batch}x{args.frames}x22x3: {best:.3f} s (best of {args.repeats})")
    print({k: round(v, 4) for k, v in result.items()})


if __name__ == "__main__":
    main()
