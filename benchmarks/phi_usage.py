"""Does a trained SimDiff model read φ? Twin-batch losses and response R² (simdiff.eval.phi_usage) as JSON.

    python benchmarks/phi_usage.py --model runs/adapters/model --data aug --batches 20 --out phi_usage.json

``--data`` is a paired simulator-augmented corpus (``simdiff data augment --mode paired``); the scores are on
its ``--split`` (the adapters' own training pairs unless another split is given: say which in a report).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--model", type=Path, required=True, help="a SimDiff model folder (continuous φ)")
    p.add_argument("--data", type=Path, required=True, help="a paired simulator-augmented corpus")
    p.add_argument("--split", default="train")
    p.add_argument("--batches", type=int, default=20)
    p.add_argument("--batch-size", type=int, default=64)
    p.add_argument("--seed", type=int, default=12345)
    p.add_argument("--t-min", type=int, default=0, help="draw t from [t_min, t_max)")
    p.add_argument("--t-max", type=int, default=1000)
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--out", type=Path, help="write the JSON here too (atomically)")
    args = p.parse_args(argv)

    import torch

    from simdiff.data.augment import open_training_dataset
    from simdiff.errors import SimdiffError
    from simdiff.eval.phi_usage import phi_usage
    from simdiff.model.checkpoint import atomic_write_json, load_pretrained
    from simdiff.model.simdiff_net import SimDiffNet
    from simdiff.text.base import load_text_encoder

    try:
        torch.set_num_threads(args.threads)
        network, config, _ = load_pretrained(args.model, "cpu")
        if not isinstance(network, SimDiffNet) or config.sim is None or config.sim.mode != "continuous":
            raise SimdiffError(f"{args.model}: not a SimDiff model with continuous φ")
        dataset = open_training_dataset([args.data], args.split, 0)
        start = time.perf_counter()
        result = phi_usage(network, dataset, load_text_encoder(config.text_encoder, torch.device("cpu")),
                           batches=args.batches, batch_size=args.batch_size, seed=args.seed,
                           t_min=args.t_min, t_max=args.t_max)
    except SimdiffError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    result.update(model=str(args.model), data=str(args.data), split=args.split,
                  wall_s=round(time.perf_counter() - start, 1))
    print(json.dumps(result, indent=1))
    if args.out is not None:
        atomic_write_json(result, args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
