"""Baselines: PhysDiff (simulator projection of x̂₀ during sampling)."""

from simdiff.baselines.physdiff import PHYSDIFF_TIMESTEPS, PhysDiffConfig, ProjectionHook, end_schedule, physdiff_generate

__all__ = ["PHYSDIFF_TIMESTEPS", "PhysDiffConfig", "ProjectionHook", "end_schedule", "physdiff_generate"]
