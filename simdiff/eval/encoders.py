"""Guo et al.'s text–motion encoder layers, shared by our evaluator and the official T2M loader.

Module and parameter names (``main``, ``out_net``, ``input_emb``, ``gru``, ``output_net``,
``hidden``) are those of the released ``finest.tar`` so official weights load unchanged.
"""

from __future__ import annotations

import torch
from torch import Tensor, nn
from torch.nn.utils.rnn import pack_padded_sequence


class MovementConvEncoder(nn.Module):
    """(B, T, in_dim) → (B, T // 4, out_dim): two stride-2 convolutions, then a linear."""

    def __init__(self, in_dim: int = 259, hidden: int = 512, out_dim: int = 512, dropout: float = 0.2) -> None:
        super().__init__()
        self.main = nn.Sequential(nn.Conv1d(in_dim, hidden, 4, 2, 1), nn.Dropout(dropout), nn.LeakyReLU(0.2),
                                  nn.Conv1d(hidden, out_dim, 4, 2, 1), nn.Dropout(dropout), nn.LeakyReLU(0.2))
        self.out_net = nn.Linear(out_dim, out_dim)

    def forward(self, x: Tensor) -> Tensor:
        return self.out_net(self.main(x.transpose(1, 2)).transpose(1, 2))


class BiGRUEncoder(nn.Module):
    """(B, N, in_dim) sequences with (B,) valid lengths → (B, out_dim).

    Linear embedding, a bidirectional GRU from a learned initial state, and an MLP on the two
    final states.
    """

    def __init__(self, in_dim: int, hidden: int, out_dim: int) -> None:
        super().__init__()
        self.input_emb = nn.Linear(in_dim, hidden)
        self.gru = nn.GRU(hidden, hidden, batch_first=True, bidirectional=True)
        self.output_net = nn.Sequential(nn.Linear(2 * hidden, hidden), nn.LayerNorm(hidden), nn.LeakyReLU(0.2),
                                        nn.Linear(hidden, out_dim))
        self.hidden = nn.Parameter(torch.zeros(2, 1, hidden))

    def encode(self, x: Tensor, lengths: Tensor) -> Tensor:
        """Final-state embedding of the first ``lengths[i]`` steps of each sequence."""
        lengths = lengths.clamp(min=1, max=x.shape[1]).cpu()
        packed = pack_padded_sequence(self.input_emb(x), lengths, batch_first=True, enforce_sorted=False)
        _, last = self.gru(packed, self.hidden.expand(2, x.shape[0], -1).contiguous())
        return self.output_net(torch.cat([last[0], last[1]], dim=-1))
