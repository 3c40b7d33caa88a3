"""SimDiff network: a (frozen) MDM backbone + Sim Encoder + two Motion Adapters per layer."""

from __future__ import annotations

from torch import Tensor, nn

from simdiff.model.adapter import MotionAdapter
from simdiff.model.backbone import MDMBackbone
from simdiff.model.condition import Condition
from simdiff.model.config import BackboneConfig, SimConfig
from simdiff.model.sim_encoder import SimEncoder


def adapter_bottleneck(config: SimConfig, dim: int) -> int:
    """The bottleneck width: ``config.bottleneck`` or, when 0, ``min(256, d // 2)`` (256 at d = 512)."""
    return config.bottleneck if config.bottleneck > 0 else min(256, max(8, dim // 2))


def _switched_off(alpha: float | Tensor) -> bool:
    """True when the adapters' strength α is zero for every row."""
    return not bool(alpha.any()) if isinstance(alpha, Tensor) else alpha == 0


class SimDiffNet(nn.Module):
    """Backbone with environment-conditioned adapters after every self-attention and feed-forward block.

    Without φ (``cond.env`` and ``cond.env_index`` both None), or at α = 0, it is the backbone exactly.
    The adapters use φ in both CFG halves; only the text is ever dropped.
    """

    def __init__(self, backbone_config: BackboneConfig, sim_config: SimConfig) -> None:
        super().__init__()
        d = backbone_config.latent_dim
        self.backbone = MDMBackbone(backbone_config)
        self.sim_encoder = SimEncoder(sim_config, d)
        r = adapter_bottleneck(sim_config, d)
        self.adapters = nn.ModuleList(MotionAdapter(d, r) for _ in range(2 * backbone_config.num_layers))

    def adapter_parameters(self) -> list[nn.Parameter]:
        """The parameters adapter training updates (Sim Encoder + adapters)."""
        return list(self.sim_encoder.parameters()) + list(self.adapters.parameters())

    def forward(self, x: Tensor, timesteps: Tensor, cond: Condition) -> Tensor:
        """x: (B, T, 263), timesteps: (B,) → x̂₀ (B, T, 263)."""
        if cond.env is None and cond.env_index is None or _switched_off(cond.alpha):
            # α = 0 (every row at Earth in sampling): h + 0·δ = h, so the 16 adapters are skipped, 25 % of a pass
            return self.backbone(x, timesteps, cond)
        e_sim = self.sim_encoder(cond.env, cond.env_index)
        alpha = cond.alpha

        def adapter(layer: int, position: int, h: Tensor) -> Tensor:
            return self.adapters[2 * layer + position](h, e_sim, alpha)

        return self.backbone(x, timesteps, cond, adapter=adapter)
