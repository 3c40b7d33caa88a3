"""Two-bone inverse kinematics for a leg (hip, knee, ankle), shared by the foot passes.

Positions are (..., 3) metres. The hip stays; thigh and shin keep their lengths; the knee bends in the plane it
bent in before (towards ``forward``, the body's facing, where the given leg is straight).
"""

from __future__ import annotations

import torch

REACH: float = 0.9999
"""Share of thigh + shin the solved leg may span (a fully straight knee has no bending plane)."""


def perpendicular(v: torch.Tensor, u: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
    """The part of v (..., 3) perpendicular to the unit vector u, and its length (...)."""
    p = v - (v * u).sum(-1, keepdim=True) * u
    return p, p.norm(dim=-1)


def solve_leg(hip: torch.Tensor, knee: torch.Tensor, ankle: torch.Tensor, target: torch.Tensor,
              forward: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
    """Knee and ankle (..., 3) reaching ``target`` from ``hip`` with the thigh and shin of (hip, knee, ankle).

    The ankle is ``target`` when the leg reaches it; beyond reach it is the nearest point the straightened leg
    (:data:`REACH`) gets to, on the line from the hip to ``target``.
    """
    thigh = (knee - hip).norm(dim=-1)
    shin = (ankle - knee).norm(dim=-1)
    to_target = target - hip
    u = to_target / to_target.norm(dim=-1, keepdim=True).clamp_min(1e-9)
    d = torch.minimum(torch.maximum(to_target.norm(dim=-1), (thigh - shin).abs() + 1e-6), REACH * (thigh + shin))
    along = (thigh**2 - shin**2 + d**2) / (2 * d)
    across = (thigh**2 - along**2).clamp_min(0).sqrt()
    pole, size = perpendicular(knee - hip, u)
    ahead, ahead_size = perpendicular(forward, u)
    straight = (size < 1e-4)[..., None]
    pole = torch.where(straight, ahead / ahead_size[..., None].clamp_min(1e-9), pole / size[..., None].clamp_min(1e-9))
    return hip + along[..., None] * u + across[..., None] * pole, hip + d[..., None] * u
