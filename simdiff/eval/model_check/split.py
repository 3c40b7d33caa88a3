"""The test-split figures: the T2M protocol at Earth φ, one replication per seed.

Each seed s runs :func:`simdiff.eval.protocol.evaluate_t2m` with one replication (data draw
``[s, 0]``, generation seed ``s·1000003 + batch``): n test motions (whole batches; the whole
split when smaller), one caption and crop each, generated at the GT length. Per replication the
protocol gives, for the samples and for the same motions' ground truth, sliding (mm/frame),
skate ratio, R-precision, FID and the rest; the generated FID is against this replication's GT
embeddings, the ground truth's FID (the *floor*) against a resample: the protocol's second,
independent draw of n test motions (own captions and crops; not disjoint from the first when the
split holds fewer than 2n motions). Intervals: Student-t over the replications.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from simdiff.eval import metrics as M
from simdiff.eval.model_check.config import SplitOptions
from simdiff.eval.protocol import GenerateFn, ProtocolConfig, claim_problems, evaluate_t2m
from simdiff.eval.stats import t_interval

FID_FLOOR: str = ("ground truth vs a resample: the protocol's second independent draw of n test motions "
                  "(own captions and crops), not two disjoint halves")
RATIOS: dict[str, tuple[str, str]] = {
    "skate_ratio": ("skate_ratio", "skate_ratio"),
    "r_precision_top3": ("r_precision_top3", "r_precision_top3"),
    "fid_over_floor": ("fid", "fid"),
    "sliding_over_gt": ("sliding", "sliding"),
    "sliding_own_floor_over_gt": ("sliding_own_floor", "sliding_own_floor"),
}
"""Per-replication ratios generated / ground truth (name: (generated metric, GT metric))."""


def protocol_config(options: SplitOptions, seed: int) -> ProtocolConfig:
    """One replication of ``options.n`` motions in batches of ``options.batch_size`` (smaller when n is)."""
    bs = min(options.batch_size, options.n)
    return ProtocolConfig(replications=1, batch_size=bs, samples_limit=max(options.n - bs, 0),
                          diversity_times=min(300, options.n), mm_prompts=0, physics=True, seed=int(seed))


def measure_split(evaluator: Any, dataset: Any, generate: GenerateFn, options: SplitOptions, seeds: list[int],
                  progress: bool = False) -> dict[str, Any]:
    """Run the protocol once per seed; summaries, per-seed rows and generated/GT ratios."""
    from tqdm import tqdm

    gen_rows, gt_rows, seconds, n_used = [], [], [], []
    for seed in tqdm(seeds, desc="test split", disable=not progress, dynamic_ncols=True):
        result = evaluate_t2m(evaluator, dataset, generate, protocol_config(options, seed))
        rep = result["replications"][0]
        gen_rows.append(rep["generated"])
        gt_rows.append(rep["ground_truth"])
        seconds.append(rep["gen_s_per_sample"])
        n_used.append(result["samples_per_replication"])
    ratios = {}
    for name, (g, t) in RATIOS.items():
        values = [_ratio(gr[g], tr[t]) for gr, tr in zip(gen_rows, gt_rows)]
        finite = [v for v in values if np.isfinite(v)]
        mean, half = t_interval(finite) if finite else (float("nan"), float("nan"))
        ratios[name] = {"mean": mean, "ci95": half, "per_seed": values}
    batch = protocol_config(options, seeds[0]).batch_size
    whole = n_used[0] < options.n and n_used[0] == len(dataset) // batch * batch
    return {
        "split": options.split, "split_size": len(dataset), "n_requested": options.n,
        "samples_per_replication": n_used[0], "whole_split": whole, "batch_size": batch,
        "r_precision_comparable": batch == 32, "replications": len(seeds), "seeds": list(seeds),
        "data_draw_seeds": [[s, 0] for s in seeds],
        "generation_seeds": [[s * 1_000_003 + k for k in range(n_used[0] // batch)] for s in seeds],
        "env": "Earth (-9.81, 0, 0)", "fid_floor": FID_FLOOR,
        "claim_problems": claim_problems(dataclasses.replace(protocol_config(options, seeds[0]), replications=len(seeds)),
                                         len(dataset)) + ([] if batch == 32 else [f"R-precision batch {batch}, not 32"]),
        "generated": M.summarize(gen_rows), "ground_truth": M.summarize(gt_rows), "ratios": ratios,
        "per_seed": {"generated": gen_rows, "ground_truth": gt_rows}, "gen_s_per_sample": float(np.mean(seconds)),
        "protocol": dataclasses.asdict(protocol_config(options, seeds[0])) | {"seed": "per replication"},
    }


def _ratio(a: float, b: float) -> float:
    return float(a) / float(b) if b else float("nan")
