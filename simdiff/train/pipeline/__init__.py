"""``simdiff train pipeline``: corpus → augmentation → backbone → adapters → evaluator → evaluation → export.

Each stage writes ``<out>/stages/<name>.json`` (a done-marker holding a hash of its settings and
of its inputs' markers) and is skipped when that hash is current; a changed setting re-runs its
stage and every stage downstream. Interrupted stages resume (trainers from checkpoints, the
augmentation from shards, the evaluator from its epoch checkpoint).
"""

from simdiff.train.pipeline.config import BUDGETS, PipelineConfig, budget_config
from simdiff.train.pipeline.runner import StagePlan, plan_pipeline, run_pipeline

__all__ = ["BUDGETS", "PipelineConfig", "StagePlan", "budget_config", "plan_pipeline", "run_pipeline"]
