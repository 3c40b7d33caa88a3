"""The HumanML3D evaluation protocol (facts §3.4) around any evaluator and any generator.

Per replication r (seeded ``[seed, r]``): shuffle the test items, take full batches of 32
(``drop_last``) up to ``samples_limit`` (MDM: ``1000 // 32 + 1`` batches), draw each item's
caption and crop (multiple of 4 frames, MDM's 2/3–1/3 rule), generate one motion per caption
with the GT length, embed GT and generated motions and the texts, and compute

* generated: R-precision top-1/2/3, MM-Dist, FID against this replication's GT motion
  embeddings, Diversity (300 pairs), physics metrics (CLoSD's per-batch mean), floating_to_gt
  (|floating − the same captions' GT floating|, mm) and phys_err (penetration + sliding +
  floating_to_gt, mm; see :func:`simdiff.motion.metrics.phys_err`), never_touch (fraction of
  samples whose lowest joint never comes within 0.10 m of y = 0, :func:`simdiff.motion.metrics.never_touches`);
* ground truth: the same, with FID against a second independent GT draw (crops/captions);
* MultiModality (``mm_prompts`` > 0): ``mm_repeats`` generations for each of ``mm_prompts``
  captions, ``mm_times`` pairs each.

Results: per-replication values and mean ± the Student-t 95 % half-width (:mod:`simdiff.eval.stats`).

FID is biased upwards at small n (the sample covariance of n embeddings has rank ≤ n − 1):
the ground-truth row's FID (GT against an independent GT draw at the *same* n) is the floor
a generated row's FID must be read against. Claim-carrying runs use n ≥ 256 motions per
replication (or the whole split in whole batches, when smaller) and R ≥ 5
(:data:`MIN_CLAIM_SAMPLES`, :data:`MIN_CLAIM_REPLICATIONS`).

``generate(captions, lengths, seed) -> (B, T, 263)`` must return *raw* (un-normalised)
features, zero beyond each length (``MotionGenerator.generate(...).features``).
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Callable, Protocol

import numpy as np
import torch
from torch import Tensor

from simdiff.diffusion.config import SamplingConfig
from simdiff.errors import SimdiffError
from simdiff.eval import metrics as M

GenerateFn = Callable[[list[str], list[int], int], Tensor]
MIN_CLAIM_SAMPLES: int = 256
"""Motions per replication a claim-carrying protocol needs (or the whole split, when smaller)."""
MIN_CLAIM_REPLICATIONS: int = 5
"""Replications a claim-carrying protocol needs."""


class Evaluator(Protocol):
    """What the protocol needs from an evaluator (ours or the official T2M one)."""

    name: str

    def embed_motion(self, features: Tensor, lengths: Tensor | Sequence[int]) -> np.ndarray: ...

    def embed_text(self, captions: Sequence[str], tokens: Sequence[Sequence[str]] | None = None) -> np.ndarray: ...


@dataclass
class ProtocolConfig:
    """Protocol constants (defaults: MDM's ``wo_mm``; ``mm_short`` sets mm_prompts=100, replications=5).

    Attributes:
        replications: R (MDM 20).
        batch_size: R-precision batch (must be 32 for comparable numbers).
        samples_limit: generated samples per replication (MDM 1000 → 32 batches).
        diversity_times: pairs for Diversity (300).
        mm_prompts, mm_repeats, mm_times: MultiModality (100, 30, 10); 0 prompts = off.
        physics: also compute the physics metrics of generated and GT motions.
        seed: base seed of data draws and generation noise.
    """

    replications: int = 20
    batch_size: int = 32
    samples_limit: int = 1000
    diversity_times: int = 300
    mm_prompts: int = 0
    mm_repeats: int = 30
    mm_times: int = 10
    physics: bool = True
    seed: int = 0

    @property
    def max_batches(self) -> int:
        return self.samples_limit // self.batch_size + 1

    def generation_seed(self, replication: int) -> int:
        """Noise seed of batch 0 of a replication (batch k adds k)."""
        return self.seed * 1_000_003 + replication * 1009

    def seeds_used(self) -> dict[str, Any]:
        """The seeds of a run (stated in every report): data draws and generation noise per replication."""
        return {"base": self.seed, "data_draw": [[self.seed, r] for r in range(self.replications)],
                "generation": [self.generation_seed(r) for r in range(self.replications)],
                "note": "batch k of replication r adds k to its generation seed"}


def _draw(dataset: Any, rng: np.random.Generator, config: ProtocolConfig) -> list[dict[str, Any]]:
    """This replication's batches of collated GT items (raw features added)."""
    from simdiff.data.batch import collate

    n_batches = min(config.max_batches, len(dataset) // config.batch_size)
    if n_batches == 0:
        raise SimdiffError(f"the evaluation split has {len(dataset)} items, fewer than one batch of {config.batch_size}")
    order = rng.permutation(len(dataset))
    batches = []
    for b in range(n_batches):
        items = [dataset.get(int(i), rng) for i in order[b * config.batch_size : (b + 1) * config.batch_size]]
        batch = collate(items)
        batch["tokens"] = [it.get("tokens", []) for it in items]
        batch["raw"] = dataset.normalizer.denormalize(batch["motion"]) * batch["mask"][..., None]
        batches.append(batch)
    return batches


def _physics(features: Tensor, lengths: Tensor, foot_lock: float | None = None) -> dict[str, float]:
    """Physics metrics of ground truth's stored positions (``foot_lock`` None) or of the joints a user gets for
    generated features (smoothed, rigid, planted feet held at ``foot_lock``)."""
    from simdiff.motion.features import features_to_joints
    from simdiff.motion.metrics import never_touches, own_floor_metrics, physics_metrics
    from simdiff.motion.rigid import batch_joints_from_features

    if foot_lock is None:
        joints = features_to_joints(features.detach().cpu().double()).numpy()
    else:
        joints = batch_joints_from_features(features, lengths, foot_lock)
    lens = lengths.cpu().clamp(min=2, max=joints.shape[1]).numpy()
    return {**physics_metrics(joints, lens), **own_floor_metrics(joints, lens),
            "never_touch": float(never_touches(joints, lens).mean())}


def _scores(text: np.ndarray, motion: np.ndarray, ref_motion: np.ndarray, config: ProtocolConfig,
            rng: np.random.Generator) -> dict[str, float]:
    stats = M.matching_metrics(text, motion, config.batch_size)
    out = {"r_precision_top1": float(stats.r_precision[0]), "r_precision_top2": float(stats.r_precision[1]),
           "r_precision_top3": float(stats.r_precision[2]), "mm_dist": stats.mm_dist, "fid": M.fid(motion, ref_motion)}
    times = min(config.diversity_times, len(motion))
    out["diversity"] = M.diversity(motion, times, rng)
    return out


def evaluate_t2m(evaluator: Evaluator, dataset: Any, generate: GenerateFn | None, config: ProtocolConfig = ProtocolConfig(),
                 progress: bool = False) -> dict[str, Any]:
    """Run the protocol; ``generate=None`` evaluates the ground truth only.

    Args:
        evaluator: embeds motions (raw features) and texts.
        dataset: the test split as a :class:`simdiff.data.humanml3d.HumanML3D` (``get(i, rng)``, ``normalizer``).
        generate: the model under test (see module docstring).
    Returns:
        {"replications": [{"generated": {...}, "ground_truth": {...}, "gen_s_per_sample"}],
         "summary": {"generated": {metric: {mean, ci95, n}}, "ground_truth": {...}}, "samples_per_replication"}.
    """
    from tqdm import tqdm

    reps = []
    bar = tqdm(range(config.replications), desc="replications", disable=not progress, dynamic_ncols=True)
    for r in bar:
        rng = np.random.default_rng([config.seed, r])
        batches = _draw(dataset, rng, config)
        second = _draw(dataset, np.random.default_rng([config.seed, r, 1]), config)
        text = np.concatenate([evaluator.embed_text(b["captions"], b["tokens"]) for b in batches])
        gt = np.concatenate([evaluator.embed_motion(b["raw"], b["lengths"]) for b in batches])
        gt2 = np.concatenate([evaluator.embed_motion(b["raw"], b["lengths"]) for b in second])
        row: dict[str, Any] = {"ground_truth": _scores(text, gt, gt2, config, np.random.default_rng([config.seed, r, 2]))}
        if config.physics:
            row["ground_truth"].update(_mean_dicts([_physics(b["raw"], b["lengths"]) for b in batches]))
        if generate is not None:
            gen_emb, phys, seconds = [], [], 0.0
            for k, b in enumerate(batches):
                start = time.perf_counter()
                feats = generate(list(b["captions"]), [int(n) for n in b["lengths"]], config.generation_seed(r) + k)
                seconds += time.perf_counter() - start
                gen_emb.append(evaluator.embed_motion(feats, b["lengths"]))
                if config.physics:
                    phys.append(_physics(feats, b["lengths"], getattr(generate, "foot_lock", 0.0)))
            gen = np.concatenate(gen_emb)
            row["generated"] = _scores(text, gen, gt, config, np.random.default_rng([config.seed, r, 3]))
            if phys:
                row["generated"].update(_mean_dicts(phys))
                gt_float = row["ground_truth"]["floating"]
                row["generated"]["floating_to_gt"] = abs(row["generated"]["floating"] - gt_float)
                row["generated"]["phys_err"] = phys_err(row["generated"], gt_float)
            if config.mm_prompts > 0:
                row["generated"]["multimodality"] = _multimodality(evaluator, batches, generate, config, r)
            row["gen_s_per_sample"] = seconds / len(gen)
        reps.append(row)
    summary = {key: M.summarize([rep[key] for rep in reps]) for key in ("ground_truth", "generated") if key in reps[0]}
    return {"replications": reps, "summary": summary, "samples_per_replication": len(text),
            "split_size": len(dataset), "protocol": {**config.__dict__}}


def phys_err(metrics: dict[str, float], gt_floating: float) -> float:
    """Penetration + sliding + |floating − GT floating| (mm): :func:`simdiff.motion.metrics.phys_err`."""
    from simdiff.motion.metrics import phys_err as _phys_err

    return _phys_err(metrics, gt_floating)


def claim_problems(config: ProtocolConfig, split_size: int | None) -> list[str]:
    """Why ``config`` cannot carry a claim on a split of ``split_size`` items (empty: it can).

    n per replication must be ≥ :data:`MIN_CLAIM_SAMPLES`, or every whole batch of the split when
    the split is smaller; R ≥ :data:`MIN_CLAIM_REPLICATIONS`.
    """
    out = []
    if config.replications < MIN_CLAIM_REPLICATIONS:
        out.append(f"replications={config.replications} < {MIN_CLAIM_REPLICATIONS}")
    whole = None if split_size is None else split_size // config.batch_size
    n = config.max_batches * config.batch_size if whole is None else min(config.max_batches, whole) * config.batch_size
    if n < MIN_CLAIM_SAMPLES and (whole is None or config.max_batches < whole):
        out.append(f"samples_limit={config.samples_limit} gives {n} motions per replication, fewer than "
                   f"{MIN_CLAIM_SAMPLES} and fewer than the whole split")
    return out


def _mean_dicts(rows: list[dict[str, float]]) -> dict[str, float]:
    return {k: float(np.mean([r[k] for r in rows])) for k in rows[0]}


def _multimodality(evaluator: Evaluator, batches: list[dict[str, Any]], generate: GenerateFn, config: ProtocolConfig,
                   r: int) -> float:
    captions = [c for b in batches for c in b["captions"]][: config.mm_prompts]
    lengths = [int(n) for b in batches for n in b["lengths"]][: config.mm_prompts]
    embs = []
    for p, (cap, n) in enumerate(zip(captions, lengths)):
        feats = generate([cap] * config.mm_repeats, [n] * config.mm_repeats, config.seed * 7919 + r * 131 + p)
        embs.append(evaluator.embed_motion(feats, [n] * config.mm_repeats))
    return M.multimodality(np.stack(embs), min(config.mm_times, config.mm_repeats), np.random.default_rng([config.seed, r, 4]))


def generator_fn(generator: Any, sampling: SamplingConfig = SamplingConfig(), *, env: Sequence[float] | None = None,
                 env_index: int | None = None, physdiff: Any = None, projector: Any = None, simulate: bool = False,
                 finish_projector: Any = None) -> GenerateFn:
    """A :data:`GenerateFn` over a :class:`simdiff.inference.generator.MotionGenerator` sampling with ``sampling``
    (e.g. the shipped model's :func:`simdiff.inference.default.sampling_config`), optionally with PhysDiff
    projection (``physdiff``: its sampler, steps and guidance replace ``sampling``'s; η must be 0).

    ``simulate``: the simulated finish: every final sample is re-tracked by ``finish_projector``
    (default ``projector``) under φ (``env``, Earth when None) and its features are replaced by the
    rollout's where it tracked (frames after a fall keep the generated ones, as a PhysDiff
    projection does). The returned function's ``finish_log`` lists one entry per finished sample
    (``success``: tracked to the end; ``frames_replaced``), in generation order.
    """
    if sampling.eta and physdiff is not None:
        raise SimdiffError(f"DDIM eta {sampling.eta:g} is a generator option; the PhysDiff baseline takes none "
                           "(leave it at 0)")
    finish_log: list[dict[str, Any]] = []

    def generate(captions: list[str], lengths: list[int], seed: int) -> Tensor:
        phi = {"env": env, "env_index": env_index} if generator.is_simdiff else {}
        if physdiff is not None:
            from simdiff.baselines.physdiff import physdiff_generate

            out, _ = physdiff_generate(generator, captions, lengths, physdiff, projector=projector, seed=seed,
                                       sampling=sampling, **phi)
        else:
            out = generator.generate(captions, lengths, sampling, seed=seed, **phi)
        feats = out.features.detach().cpu()
        if simulate:
            feats = simulated_finish(generator, feats, lengths, env, finish_projector or projector, log=finish_log)
        return feats

    generate.finish_log = finish_log  # type: ignore[attr-defined]
    # the planted-feet hold of the written joints; a PhysDiff projection or a simulated finish is measured as is
    generate.foot_lock = 0.0 if physdiff is not None or simulate else sampling.foot_lock  # type: ignore[attr-defined]
    return generate


def finish_summary(log: Sequence[dict[str, Any]]) -> dict[str, Any]:
    """How many of the finished samples of a :func:`generator_fn` ``finish_log`` tracked to the end, had a
    second try (:mod:`simdiff.sim.fallback`) and kept its rollout."""
    tracked = sum(bool(e["success"]) for e in log)
    return {"motions": len(log), "tracked": tracked, "tracked_frac": tracked / max(1, len(log)),
            "second_tries": sum(int(e.get("attempts", 1)) > 1 for e in log),
            "fallback_kept": sum(bool(e.get("fallback", False)) for e in log)}


def simulated_finish(generator: Any, features: Tensor, lengths: Sequence[int], env: Sequence[float] | None,
                     projector: Any, log: list[dict[str, Any]] | None = None) -> Tensor:
    """(B, T, 263) raw features → the same with each motion replaced by its re-tracked rollout under φ.

    ``log``, when given, gets one entry per motion: ``success`` (tracked to the end), ``frames_replaced``,
    ``attempts`` (rollouts simulated) and ``fallback`` (the second try's rollout was kept).
    """
    from simdiff.baselines.physdiff import ProjectionHook
    from simdiff.motion.normalize import Normalizer
    from simdiff.sim.env import Environment

    if projector is None:
        raise SimdiffError("the simulated finish needs a projector (the simulator)")
    norm = Normalizer(generator.mean.cpu().numpy(), generator.std.cpu().numpy())
    phi = Environment(*env) if env is not None else Environment()
    hook = ProjectionHook(norm, [int(n) for n in lengths], phi, projector)
    x0 = norm.normalize(features.float())
    out = norm.denormalize(hook(x0, 0, x0))
    if log is not None:
        log.extend({"success": e["success"], "frames_replaced": e["frames_replaced"], "attempts": e["attempts"],
                    "fallback": e["fallback"]} for e in hook.log[-1]["samples"])
    mask = (torch.arange(out.shape[1])[None, :] < torch.as_tensor([int(n) for n in lengths])[:, None]).to(out.dtype)
    return out * mask[..., None]
