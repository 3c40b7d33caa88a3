"""T2M metrics on inputs whose answers are known."""

from __future__ import annotations

import numpy as np
import pytest

from simdiff.errors import SimdiffError
from simdiff.eval import metrics as M


def test_distance_matrix_matches_brute_force() -> None:
    rng = np.random.default_rng(0)
    a, b = rng.normal(size=(5, 7)), rng.normal(size=(4, 7))
    brute = np.linalg.norm(a[:, None] - b[None], axis=-1)
    assert np.allclose(M.euclidean_distance_matrix(a, b), brute, atol=1e-9)


def test_fid_of_a_set_with_itself_is_zero() -> None:
    x = np.random.default_rng(1).normal(size=(500, 16))
    assert abs(M.fid(x, x)) < 1e-6


def test_fid_of_shifted_set_is_squared_shift() -> None:
    x = np.random.default_rng(2).normal(size=(400, 8)) @ np.diag(np.linspace(0.5, 2.0, 8))
    shift = np.linspace(-1.0, 1.0, 8)
    assert M.fid(x, x + shift) == pytest.approx(float(shift @ shift), abs=1e-5)


def test_frechet_distance_analytic_diagonal_gaussians() -> None:
    a, b = np.array([1.0, 4.0, 0.25]), np.array([4.0, 1.0, 1.0])
    mu1, mu2 = np.zeros(3), np.array([1.0, 2.0, -2.0])
    expected = 9.0 + float(np.sum(a + b - 2 * np.sqrt(a * b)))
    assert M.frechet_distance(mu1, np.diag(a), mu2, np.diag(b)) == pytest.approx(expected, rel=1e-9)


def test_fid_of_sampled_gaussians_approaches_analytic() -> None:
    rng = np.random.default_rng(3)
    x = rng.normal(size=(20000, 4))
    y = rng.normal(size=(20000, 4)) * 2.0 + 3.0
    expected = 4 * 9.0 + 4 * (1 + 4 - 2 * 2)
    assert M.fid(x, y) == pytest.approx(expected, rel=0.03)


def test_r_precision_of_a_perfect_evaluator_is_one() -> None:
    emb = np.random.default_rng(4).normal(size=(96, 32)) * 10
    stats = M.matching_metrics(emb, emb)
    assert np.allclose(stats.r_precision, [1.0, 1.0, 1.0])
    assert stats.mm_dist == pytest.approx(0.0, abs=1e-6)
    assert stats.count == 96


def test_r_precision_of_known_ranks() -> None:
    # distances built so that row i's true motion ranks i % 4 (0-based) in every batch
    n = 32
    hits = M.top_k_hits(np.array([[0 if j == i else 1 + ((j - i) % n) for j in range(n)] for i in range(n)], float))
    assert hits.tolist() == [32, 32, 32]
    dist = np.ones((n, n))
    for i in range(n):
        r = i % 4
        dist[i, i] = 1.0 + r  # true one at distance 1 + r
        others = [j for j in range(n) if j != i][:3]
        for j, d in zip(others, (1.5, 2.5, 3.5)):
            dist[i, j] = d
        for j in range(n):
            if j != i and j not in others:
                dist[i, j] = 10.0
    # rank: r=0 → 0, r=1 → 1, r=2 → 2, r=3 → 3  → top1 8, top2 16, top3 24
    assert M.top_k_hits(dist).tolist() == [8, 16, 24]


def test_r_precision_drops_partial_batches_and_needs_one() -> None:
    emb = np.random.default_rng(5).normal(size=(40, 8))
    assert M.matching_metrics(emb, emb).count == 32
    with pytest.raises(SimdiffError, match="at least 32"):
        M.matching_metrics(emb[:10], emb[:10])


def test_mm_dist_is_mean_paired_distance() -> None:
    t = np.zeros((32, 2))
    m = np.zeros((32, 2))
    m[:, 0] = 3.0
    assert M.matching_metrics(t, m).mm_dist == pytest.approx(3.0)


def test_diversity_of_known_set() -> None:
    # half the points at 0, half at (d, 0): random pairs differ with probability 1/2
    d = 4.0
    emb = np.zeros((2000, 2))
    emb[1000:, 0] = d
    assert M.diversity(emb, 300, np.random.default_rng(0)) == pytest.approx(d / 2, rel=0.15)
    const = np.ones((300, 5))
    assert M.diversity(const, 300) == 0.0
    with pytest.raises(SimdiffError, match="300"):
        M.diversity(const[:10])


def test_multimodality_of_known_set() -> None:
    # every prompt's repeats lie on two points 2 apart, 15 and 15
    emb = np.zeros((5, 30, 3))
    emb[:, 15:, 1] = 2.0
    mm = M.multimodality(emb, 10, np.random.default_rng(1))
    assert 0.0 < mm < 2.0
    assert M.multimodality(np.ones((3, 10, 4)), 10) == 0.0


def test_mean_ci_is_student_t() -> None:
    from scipy import stats

    values = [1.0, 2.0, 3.0, 4.0]
    mean, ci = M.mean_ci(values)
    assert mean == 2.5
    # closed form: t_{0.975, 3} * s / sqrt(4), s with ddof = 1 (wider than MDM's 1.96 * population std / 2)
    assert ci == pytest.approx(stats.t.ppf(0.975, 3) * np.std(values, ddof=1) / 2.0)
    assert ci > 1.96 * np.std(values) / 2.0
    summary = M.summarize([{"fid": 1.0, "div": 2.0}, {"fid": 3.0, "div": 2.0}])
    assert summary["fid"]["mean"] == 2.0 and summary["fid"]["n"] == 2
    assert summary["fid"]["ci95"] == pytest.approx(stats.t.ppf(0.975, 1) * np.sqrt(2.0) / np.sqrt(2))
    assert summary["div"]["ci95"] == 0.0
