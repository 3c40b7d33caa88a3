"""Motion Adapter: a zero-initialised residual bottleneck conditioned on e_sim."""

from __future__ import annotations

from torch import Tensor, nn


class MotionAdapter(nn.Module):
    """``h' = h + α · W_up σ(W_down (h + e_sim W_sim))`` with σ = SiLU.

    ``W_up`` (weight and bias) starts at zero, so a fresh adapter is the identity exactly.

    Args:
        dim: model width d.
        bottleneck: hidden width r of the bottleneck.
    """

    def __init__(self, dim: int, bottleneck: int) -> None:
        super().__init__()
        self.sim = nn.Linear(dim, dim, bias=False)
        self.down = nn.Linear(dim, bottleneck)
        self.act = nn.SiLU()
        self.up = nn.Linear(bottleneck, dim)
        nn.init.zeros_(self.up.weight)
        nn.init.zeros_(self.up.bias)

    def forward(self, h: Tensor, e_sim: Tensor, alpha: float | Tensor = 1.0) -> Tensor:
        """h: (B, S, d), e_sim: (B, d), alpha: float or (B,) → (B, S, d)."""
        delta = self.up(self.act(self.down(h + self.sim(e_sim)[:, None, :])))
        if isinstance(alpha, Tensor):
            alpha = alpha.to(h.dtype).reshape(-1, 1, 1)
        return h + alpha * delta
