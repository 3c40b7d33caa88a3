"""Text-to-motion metrics with the standard HumanML3D protocol (Guo et al. 2022, MDM).

All functions take embeddings from an evaluator (``(N, D)`` float arrays; D = 512 for the
official T2M evaluator) and return plain floats. Conventions follow
``/work/shared/reference/humanml3d-mdm-evaluation-facts.md`` §3.3:

* Euclidean distance matrix ``sqrt(max(0, |a|² − 2 a·b + |b|²))``;
* R-precision top-k: per batch of 32 pairs, rank the 32 motions by distance to each text;
  a hit when the paired motion is among the first k (cumulative in k); summed over batches,
  divided by the number of pairs scored;
* MM-Dist: mean text-to-paired-motion distance;
* FID: ``|μ1−μ2|² + Tr(Σ1 + Σ2 − 2·sqrtm(Σ1Σ2))`` with ``np.cov(rowvar=False)``; 1e-6·I is
  added to both covariances if ``sqrtm`` is not finite; the real part is kept;
* Diversity: mean L2 distance between two independent draws of ``times`` (300) embeddings;
* MultiModality: per prompt, mean L2 distance between ``times`` (10) random pairs of its
  repeats, averaged over prompts;
* reporting: mean and the Student-t 95 % half-width ``t_{0.975,R−1}·s/√R`` over R replications
  (sample std; MDM's normal-theory ``1.96·σ/√R`` understates it at small R), see :mod:`simdiff.eval.stats`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy import linalg

from simdiff.errors import SimdiffError

R_PRECISION_BATCH: int = 32
"""Pairs per R-precision batch (the protocol requires exactly 32)."""
DIVERSITY_TIMES: int = 300
MM_TIMES: int = 10
TOP_K: int = 3


def _as_2d(x: np.ndarray, name: str) -> np.ndarray:
    arr = np.asarray(x, dtype=np.float64)
    if arr.ndim != 2:
        raise SimdiffError(f"{name} must be (N, D) embeddings, got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise SimdiffError(f"{name} contains NaN or infinite values")
    return arr


def euclidean_distance_matrix(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(N, D), (M, D) → (N, M) pairwise L2 distances."""
    a, b = _as_2d(a, "a"), _as_2d(b, "b")
    if a.shape[1] != b.shape[1]:
        raise SimdiffError(f"embedding sizes differ: {a.shape[1]} vs {b.shape[1]}")
    sq = (a**2).sum(1)[:, None] - 2.0 * a @ b.T + (b**2).sum(1)[None, :]
    return np.sqrt(np.maximum(sq, 0.0))


def top_k_hits(dist: np.ndarray, k: int = TOP_K) -> np.ndarray:
    """(N, N) text×motion distances → (k,) number of rows whose diagonal is within top 1..k."""
    order = np.argsort(dist, axis=1, kind="stable")
    rank = np.argmax(order == np.arange(len(dist))[:, None], axis=1)  # 0-based rank of the true motion
    return np.array([(rank < j).sum() for j in range(1, k + 1)], dtype=np.float64)


@dataclass
class MatchingStats:
    """R-precision (top-1..k fractions) and MM-Dist over the batches scored."""

    r_precision: np.ndarray
    mm_dist: float
    count: int


def matching_metrics(text_emb: np.ndarray, motion_emb: np.ndarray, batch_size: int = R_PRECISION_BATCH,
                     k: int = TOP_K) -> MatchingStats:
    """R-precision and MM-Dist of paired embeddings, scored in consecutive batches.

    Args:
        text_emb, motion_emb: (N, D) row i of each is one pair. Only full batches are scored
            (the protocol's loaders use ``drop_last=True``); N must be ≥ ``batch_size``.
        batch_size: 32 in the protocol.
    """
    t, m = _as_2d(text_emb, "text_emb"), _as_2d(motion_emb, "motion_emb")
    if t.shape != m.shape:
        raise SimdiffError(f"text and motion embeddings must pair up, got {t.shape} and {m.shape}")
    n_batches = len(t) // batch_size
    if n_batches == 0:
        raise SimdiffError(f"R-precision needs at least {batch_size} pairs, got {len(t)}")
    hits = np.zeros(k)
    dist_sum = 0.0
    for i in range(n_batches):
        sl = slice(i * batch_size, (i + 1) * batch_size)
        dist = euclidean_distance_matrix(t[sl], m[sl])
        hits += top_k_hits(dist, k)
        dist_sum += float(np.trace(dist))
    count = n_batches * batch_size
    return MatchingStats(r_precision=hits / count, mm_dist=dist_sum / count, count=count)


def activation_statistics(emb: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(N, D) → (mean (D,), covariance (D, D)) with ``np.cov(rowvar=False)``."""
    e = _as_2d(emb, "embeddings")
    if len(e) < 2:
        raise SimdiffError("FID statistics need at least 2 embeddings")
    return e.mean(0), np.cov(e, rowvar=False)


def frechet_distance(mu1: np.ndarray, sigma1: np.ndarray, mu2: np.ndarray, sigma2: np.ndarray,
                     eps: float = 1e-6) -> float:
    """Fréchet distance between N(μ1, Σ1) and N(μ2, Σ2)."""
    mu1, mu2 = np.atleast_1d(mu1), np.atleast_1d(mu2)
    sigma1, sigma2 = np.atleast_2d(sigma1), np.atleast_2d(sigma2)
    if mu1.shape != mu2.shape or sigma1.shape != sigma2.shape:
        raise SimdiffError("FID statistics have different sizes")
    diff = mu1 - mu2
    with np.errstate(all="ignore"):
        covmean = linalg.sqrtm(sigma1 @ sigma2)
    if not np.all(np.isfinite(covmean)):
        offset = np.eye(sigma1.shape[0]) * eps
        covmean = linalg.sqrtm((sigma1 + offset) @ (sigma2 + offset))
    covmean = np.real(covmean)
    return float(diff @ diff + np.trace(sigma1) + np.trace(sigma2) - 2.0 * np.trace(covmean))


def fid(emb_a: np.ndarray, emb_b: np.ndarray) -> float:
    """FID between two (N, D) embedding sets."""
    return frechet_distance(*activation_statistics(emb_a), *activation_statistics(emb_b))


def diversity(emb: np.ndarray, times: int = DIVERSITY_TIMES, rng: np.random.Generator | None = None) -> float:
    """Mean L2 distance between two independent ``times``-subsets (each without replacement)."""
    e = _as_2d(emb, "embeddings")
    if len(e) < times:
        raise SimdiffError(f"diversity needs at least {times} embeddings, got {len(e)}")
    rng = rng if rng is not None else np.random.default_rng(0)
    first = rng.choice(len(e), times, replace=False)
    second = rng.choice(len(e), times, replace=False)
    return float(np.linalg.norm(e[first] - e[second], axis=1).mean())


def multimodality(emb: np.ndarray, times: int = MM_TIMES, rng: np.random.Generator | None = None) -> float:
    """MultiModality of (P, R, D) embeddings: P prompts × R repeats each.

    For each prompt, two independent draws of ``times`` repeats (without replacement),
    mean paired L2 distance; averaged over prompts.
    """
    e = np.asarray(emb, dtype=np.float64)
    if e.ndim != 3:
        raise SimdiffError(f"multimodality needs (prompts, repeats, D) embeddings, got shape {e.shape}")
    if e.shape[1] < times:
        raise SimdiffError(f"multimodality needs at least {times} repeats per prompt, got {e.shape[1]}")
    rng = rng if rng is not None else np.random.default_rng(0)
    first = rng.choice(e.shape[1], times, replace=False)
    second = rng.choice(e.shape[1], times, replace=False)
    return float(np.linalg.norm(e[:, first] - e[:, second], axis=-1).mean())


def mean_ci(values: Sequence[float] | np.ndarray) -> tuple[float, float]:
    """(mean, 95% Student-t half-interval) over R replications (:func:`simdiff.eval.stats.t_interval`)."""
    from simdiff.eval.stats import t_interval

    return t_interval(values)


def summarize(replications: Sequence[dict[str, float]]) -> dict[str, dict[str, float]]:
    """{metric: {"mean", "ci95" (Student-t half-width), "sd" (ddof 1), "n"}} over per-replication metric dicts."""
    if not replications:
        raise SimdiffError("no replications to summarise")
    keys = [k for k in replications[0] if all(k in r for r in replications)]
    out: dict[str, dict[str, float]] = {}
    for key in keys:
        values = np.asarray([r[key] for r in replications], dtype=np.float64)
        mean, ci = mean_ci(values)
        out[key] = {"mean": mean, "ci95": ci, "sd": float(values.std(ddof=1)) if len(values) > 1 else float("nan"),
                    "n": len(replications)}
    return out
