"""Exponential moving average of a set of parameters."""

from __future__ import annotations

import torch
from torch import Tensor, nn


class EMA:
    """``avg ← β_t·avg + (1−β_t)·param`` after each optimiser step, for the named parameters given.

    ``β_t = min(β, (1 + t) / (10 + t))`` at optimiser step ``t`` (the usual warm-up): without it the
    initial random weights would still weigh ``β^t`` in the average (37 % after 1,000 steps at
    β = 0.999), which ruins short runs.

    Args:
        named_params: ``{name: parameter}`` of the trained parameters.
        decay: β, the decay reached once warmed up.
    """

    def __init__(self, named_params: dict[str, nn.Parameter], decay: float = 0.9999) -> None:
        self.decay = decay
        self.params = named_params
        self.shadow: dict[str, Tensor] = {k: p.detach().clone() for k, p in named_params.items()}

    def decay_at(self, step: int | None) -> float:
        """β_t for optimiser step ``step`` (None: the plain β)."""
        return self.decay if step is None else min(self.decay, (1.0 + step) / (10.0 + step))

    @torch.no_grad()
    def update(self, step: int | None = None) -> None:
        """Fold the current parameters in; ``step`` (0-based optimiser step) enables the warm-up."""
        decay = self.decay_at(step)
        for name, param in self.params.items():
            self.shadow[name].mul_(decay).add_(param.detach(), alpha=1.0 - decay)

    def state_dict(self) -> dict[str, Tensor]:
        return dict(self.shadow)

    def load_state_dict(self, state: dict[str, Tensor]) -> None:
        for name in self.shadow:
            self.shadow[name].copy_(state[name])

    def averaged_state(self, full_state: dict[str, Tensor]) -> dict[str, Tensor]:
        """``full_state`` with the averaged values substituted for the tracked parameters."""
        out = dict(full_state)
        out.update({k: v.clone() for k, v in self.shadow.items()})
        return out
