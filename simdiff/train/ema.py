"""Exponential moving average of a set of parameters."""

from __future__ import annotations

import torch
from torch import Tensor, nn


class EMA:
    """``avg ← β·avg + (1−β)·param`` after each optimiser step, for the named parameters given.

    Args:
        named_params: ``{name: parameter}`` of the trained parameters.
        decay: β.
    """

    def __init__(self, named_params: dict[str, nn.Parameter], decay: float = 0.9999) -> None:
        self.decay = decay
        self.params = named_params
        self.shadow: dict[str, Tensor] = {k: p.detach().clone() for k, p in named_params.items()}

    @torch.no_grad()
    def update(self) -> None:
        for name, param in self.params.items():
            self.shadow[name].mul_(self.decay).add_(param.detach(), alpha=1.0 - self.decay)

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
