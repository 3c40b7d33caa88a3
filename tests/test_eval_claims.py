"""Protocol rules that let a number carry a claim: Student-t intervals, floating scored against
ground truth, n/R minimums of the full budget, α chosen off the test split."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from scipy import stats

from simdiff.errors import SimdiffError
from simdiff.eval.experiments import load_config
from simdiff.eval.experiments.rows import phys_err
from simdiff.eval.protocol import ProtocolConfig, claim_problems
from simdiff.eval.stats import bootstrap_interval, t_interval
from simdiff.motion.metrics import floating_to_gt, phys_err as motion_phys_err, physics_metrics
from simdiff.motion.synthetic import jump, walk


@pytest.mark.parametrize("values", [[1.0, 2.0], [0.3, 0.1, 0.7, 0.2, 0.9], list(np.linspace(-2, 5, 20))])
def test_t_interval_matches_scipy_closed_form(values: list[float]) -> None:
    mean, half = t_interval(values)
    n = len(values)
    lo, hi = stats.t.interval(0.95, n - 1, loc=np.mean(values), scale=stats.sem(values))
    assert mean == pytest.approx(np.mean(values))
    assert half == pytest.approx((hi - lo) / 2)
    _, half90 = t_interval(values, 0.9)
    assert half90 < half


def test_t_interval_edge_cases() -> None:
    mean, half = t_interval([4.0])
    assert mean == 4.0 and np.isnan(half)
    with pytest.raises(SimdiffError, match="no values"):
        t_interval([])
    with pytest.raises(SimdiffError, match="non-finite"):
        t_interval([1.0, float("nan")])


def test_bootstrap_interval_is_seeded_and_covers_the_estimate() -> None:
    units = list(np.random.default_rng(0).normal(1.0, 0.5, 40))
    est, lo, hi = bootstrap_interval(units, lambda u: float(np.mean(u)), resamples=300, seed=3)
    assert lo < est < hi and est == pytest.approx(np.mean(units))
    assert bootstrap_interval(units, lambda u: float(np.mean(u)), resamples=300, seed=3) == (est, lo, hi)


def _sunk(joints: np.ndarray, depth: float) -> np.ndarray:
    out = joints.copy()
    out[..., 1] -= out[..., 1].min() + depth
    return out


def test_floating_to_gt_penalises_sinking_below_ground_truth() -> None:
    gt = jump(60, height=0.3, start=20)  # real motion floats in flight
    gt_phys = physics_metrics(gt)
    assert gt_phys["floating"] > 10.0
    assert floating_to_gt(gt, gt) == 0.0
    flat = jump(60, height=0.0, start=20)  # the same motion glued to the floor: no flight, no floating
    flat_phys = physics_metrics(flat)
    assert flat_phys["floating"] < gt_phys["floating"]
    raw = lambda p: p["penetration"] + p["floating"] + p["sliding"]  # noqa: E731  PhysDiff's sum
    assert raw(flat_phys) < raw(gt_phys)  # the raw sum calls the glued motion better than ground truth
    assert floating_to_gt(flat, gt) == pytest.approx(gt_phys["floating"] - flat_phys["floating"])
    # with floating against GT the ground truth scores best
    gt_err = motion_phys_err(gt_phys, gt_phys["floating"])
    assert gt_err < motion_phys_err(flat_phys, gt_phys["floating"])
    deep = _sunk(gt, 0.05)  # pushed 5 cm into the floor: penetration and floating gap both grow
    assert motion_phys_err(physics_metrics(deep), gt_phys["floating"]) > gt_err + 40.0


def test_floating_to_gt_batched_with_lengths() -> None:
    a = np.stack([walk(30), jump(30, height=0.2, start=10)])
    lifted = a.copy()
    lifted[..., 1] += 0.02  # 2 cm above the floor everywhere: +20 mm of floating on every frame
    gap = floating_to_gt(lifted, a, [30, 30], [30, 30])
    assert gap == pytest.approx(20.0, abs=1.0)


def test_rows_phys_err_uses_the_floating_gap() -> None:
    row = {"method": "M", "summary": {"phys_err": {"mean": 3.0, "ci95": 0.1}, "floating": {"mean": 99.0}}}
    assert phys_err(row) == 3.0
    assert phys_err({"method": "M", "physics": {"penetration": 1.0, "floating": 50.0, "sliding": 1.0, "phys_err": 4.0}}) == 4.0
    assert phys_err({"method": "M", "summary": {"penetration": {"mean": 1.0}}}) is None  # old rows: re-measure
    gt = {"method": "Ground truth", "summary": {"penetration": {"mean": 1.0}, "sliding": {"mean": 2.0}, "floating": {"mean": 9.0}}}
    assert phys_err(gt) == 3.0


def test_claim_problems_n_and_replications() -> None:
    assert claim_problems(ProtocolConfig(replications=5, samples_limit=1000), 5000) == []
    assert claim_problems(ProtocolConfig(replications=5, samples_limit=1000), 100) == []  # the whole split (3 batches)
    small = claim_problems(ProtocolConfig(replications=3, samples_limit=0), 5000)
    assert any("replications=3" in p for p in small) and any("32 motions" in p for p in small)
    assert claim_problems(ProtocolConfig(replications=5, samples_limit=0), 40) == []  # 1 batch is the whole split


def _config(tmp_path: Path, kind: str, **extra) -> Path:
    cfg = {"name": kind, "kind": kind, "paths": {"backbone": "b", "adapters_binary": "a"},
           "models": [{"name": "SimDiff", "model": "adapters_binary", "env_index": 1}],
           "protocol": {"replications": 5, "samples_limit": 1000},
           "budgets": {"quick": {"about": "tiny", "set": {"protocol.replications": 2, "protocol.samples_limit": 0}}},
           **extra}
    path = tmp_path / f"eval_{kind}.json"
    path.write_text(json.dumps(cfg))
    return path


def test_full_budget_must_carry_a_claim(tmp_path: Path) -> None:
    assert load_config(_config(tmp_path, "table1", ddpm_samples=32)).protocol.replications == 5
    assert load_config(_config(tmp_path, "table1"), "quick").protocol.replications == 2  # named budgets may be small
    with pytest.raises(SimdiffError, match="replications=4 < 5"):
        load_config(_config(tmp_path, "table1", protocol={"replications": 4, "samples_limit": 1000}))
    with pytest.raises(SimdiffError, match="fewer than 256"):
        load_config(_config(tmp_path, "table1", protocol={"replications": 5, "samples_limit": 64}))
    with pytest.raises(SimdiffError, match="ddpm_samples=4 < 32"):
        load_config(_config(tmp_path, "table1", samplers=["ddpm", "ddim"], ddpm_samples=4))
    smoke = load_config(_config(tmp_path, "table1", smoke=True, protocol={"replications": 2, "samples_limit": 0}))
    assert smoke.smoke


def test_alpha_is_chosen_on_val(tmp_path: Path) -> None:
    with pytest.raises(SimdiffError, match="val split"):
        load_config(_config(tmp_path, "table2", split="test"))
    assert load_config(_config(tmp_path, "table2", split="val")).split == "val"


def test_shipped_table_configs_carry_claims() -> None:
    configs = Path(__file__).resolve().parents[1] / "configs"
    t1, t2 = load_config(configs / "eval_table1.json"), load_config(configs / "eval_table2.json")
    assert t2.split == "val" and t1.split == "test"
    for c in (t1, t2):
        assert c.protocol.replications >= 5 and c.protocol.samples_limit >= 256
    assert t1.ddpm_samples >= 32


def test_generator_fn_passes_its_sampling_config_and_refuses_eta_with_physdiff() -> None:
    """The one SamplingConfig reaches the generator as it is; PhysDiff takes no DDIM η."""
    import torch

    from simdiff.diffusion.config import SamplingConfig
    from simdiff.eval.protocol import generator_fn

    calls: list[SamplingConfig] = []

    class Stub:
        is_simdiff = False

        def generate(self, captions, lengths, config, **kwargs):  # noqa: ANN001, ANN003
            calls.append(config)
            return type("G", (), {"features": torch.zeros(len(captions), 4, 263)})()

    generator_fn(Stub())(["a"], [4], 0)
    generator_fn(Stub(), SamplingConfig(eta=1.0))(["a"], [4], 0)
    assert calls == [SamplingConfig(), SamplingConfig(eta=1.0)]
    with pytest.raises(SimdiffError, match="DDIM eta 1 is a generator option; the PhysDiff baseline takes none"):
        generator_fn(Stub(), SamplingConfig(eta=1.0), physdiff=object())
