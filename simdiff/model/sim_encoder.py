"""Sim Encoder: environment parameters φ → a d-dim embedding e_sim."""

from __future__ import annotations

import torch
from torch import Tensor, nn

from simdiff.errors import SimdiffError
from simdiff.model.config import SimConfig


class SimEncoder(nn.Module):
    """Map φ to ``e_sim`` (B, d).

    ``continuous``: φ = (g_z, w_x, w_y) (B, 3) float32 → scaled → Linear(3, 64) → SiLU → Linear(64, d).
    ``categorical``: index (B,) int64 → Embedding(n, 64) → SiLU → Linear(64, d).
    Scaling maps Earth gravity to 0 and ±``wind_scale`` N to ±1 so the MLP sees O(1) inputs.
    """

    def __init__(self, config: SimConfig, dim: int) -> None:
        super().__init__()
        if config.mode not in ("continuous", "categorical"):
            raise SimdiffError(f"sim mode must be continuous or categorical, got {config.mode!r}")
        self.config = config
        if config.mode == "continuous":
            self.embed = nn.Linear(3, config.hidden)
        else:
            self.embed = nn.Embedding(config.num_categories, config.hidden)
        self.act = nn.SiLU()
        self.proj = nn.Linear(config.hidden, dim)

    def scale(self, env: Tensor) -> Tensor:
        """(B, 3) physical φ → (B, 3) network input."""
        c = self.config
        g = (env[:, 0:1] - c.gravity_offset) / c.gravity_scale
        return torch.cat([g, env[:, 1:3] / c.wind_scale], dim=1)

    def forward(self, env: Tensor | None = None, env_index: Tensor | None = None) -> Tensor:
        """Return e_sim (B, d) from ``env`` (B, 3) or ``env_index`` (B,), whichever the mode needs."""
        if self.config.mode == "continuous":
            if env is None:
                raise SimdiffError("this model needs continuous φ = (g_z, w_x, w_y) (the 'env' entry)")
            hidden = self.embed(self.scale(env.float()))
        else:
            if env_index is None:
                raise SimdiffError("this model needs an environment category (the 'env_index' entry)")
            if int(env_index.min()) < 0 or int(env_index.max()) >= self.config.num_categories:
                raise SimdiffError(f"env_index must lie in [0, {self.config.num_categories})")
            hidden = self.embed(env_index.long())
        return self.proj(self.act(hidden))
