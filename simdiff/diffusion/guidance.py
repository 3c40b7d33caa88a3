"""Guidance on the x₀ prediction.

The networks predict x₀ from x_t. Sampling combines several predictions per step:

* **Classifier-free guidance** (CFG) on the text c, trained by dropping the text: x̃₀ = x₀(∅) + s·(x₀(c) − x₀(∅))
  with scale s (``guidance``; 1: off). Backbone-only models run exactly this; categorical (binary) SimDiff models run
  it with their adapters on at strength α and the environment category kept in both passes.
* **SimDiff** adds Motion Adapters to the frozen MDM backbone, conditioned on φ = (g_z m/s², w_x N, w_y N) through
  the Sim Encoder at strength α: x₀(c, φ). At φ_ref = Earth without wind (:data:`REFERENCE_ENV`) a motion should
  be the backbone's, and measured so it is: the adapters' own answer to Earth (α > 0 at φ_ref) costs text fidelity
  (FID) and lowers jumps on the shipped model, while their answer to a *change* of φ is what the environment
  needs. So for continuous-φ models the text guidance runs on the backbone alone, G(c) = x₀⁰(∅) + s·(x₀⁰(c) −
  x₀⁰(∅)), and φ enters as follows.
* **Wind under Earth's gravity**: x̃₀ = G(c) + [G_α(c, φ) − G_α(c, φ_ref)] + (s_e − 1)·[x₀(c, φ) − x₀(c, φ_ref)],
  G_α being CFG with the adapters at α: the adapters' answer to the wind, text guidance included, added at every
  step. Their answer itself, not the adapters' prediction at φ (which moves walks sideways whatever the wind), is
  what the wind changes.
* **Another gravity**: the sample follows its Earth sample (same noise, x̃₀ = G(c)) while the timestep is above
  ``edit_t`` T_e, then continues under φ with the adapters and **environment guidance**:
  x̃₀ = G_α(c, φ) + (s_e − 1)·(x₀(c, φ) − x₀(c, φ_ref)), the adapters' answer to φ pushed s_e times as far.
  The early, noisy steps settle what the text asks for (which motion, its path), the late ones its details
  (heights, flight times, pace), which is where gravity acts: entering φ late keeps the Earth motion the text chose
  and re-plays its details under φ, which is what adapters trained on crossed twins (the other twin's x_t, one's own
  target) learn to do. The shipped model's T_e = 950 and s_e = 1.1 were chosen among T_e ∈ {900, 950} ×
  s_e ∈ {1, 1.1, 1.2} on probe seeds (``simdiff/assets/default_model/README.md``).

**Text guidance only early** (``guidance_min_t``): below that timestep each row takes x₀(c) alone, one pass instead
of two. The shipped DDIM 16 guides its first four steps (t ≥ 749): on val, R@3 and FID within noise of DDIM 50 with
guidance at every step, at 0.32× its time (``docs/design-notes.md``).

Rows at φ_ref are exactly the backbone's. Cost per step: one 2B forward over the rows at Earth's gravity, one 4W
forward over the W wind-only ones, one 3E forward over the E rows off Earth's gravity at T_e and below when s_e ≠ 1
(halved below ``guidance_min_t``).
"""

from __future__ import annotations

from dataclasses import replace
from typing import TYPE_CHECKING, Callable, Sequence

import torch
from torch import Tensor

from simdiff.errors import SimdiffError

if TYPE_CHECKING:
    from simdiff.model.condition import Condition

Denoiser = Callable[[Tensor, Tensor, "Condition"], Tensor]
"""``denoiser(x_t (B,T,F), t (B,) int64, cond) -> x̂₀ (B,T,F)``."""

REFERENCE_ENV: tuple[float, float, float] = (-9.81, 0.0, 0.0)
"""φ_ref: Earth's gravity (m/s², along z) and no wind (N)."""


class GuidedDenoiser:
    """Wrap a denoiser with the guidance of the module.

    Args:
        denoiser: the network (MDMBackbone or SimDiffNet, or anything with the same call).
        scale: text guidance s; 1 disables it (one conditional pass).
        batched: run the conditional and unconditional passes as one 2B forward (default) instead of two B forwards.
            The text is dropped in the second half only; φ/α are kept.
        env_scale: environment guidance s_e; 1 disables it. Continuous-φ models only.
        edit_t: the last timestep (0..999) at which rows off Earth's gravity follow their Earth sample.
        reference_env: φ_ref = (g_z m/s², w_x N, w_y N).
        min_t: text guidance at timesteps ≥ ``min_t`` only; below, x₀(c) alone (one pass instead of two).
    """

    def __init__(self, denoiser: Denoiser, scale: float = 2.5, batched: bool = True, env_scale: float = 1.0,
                 edit_t: int = 950, reference_env: Sequence[float] = REFERENCE_ENV, min_t: int = 0) -> None:
        self.denoiser = denoiser
        self.scale = float(scale)
        self.min_t = int(min_t)
        self.batched = batched
        self.env_scale = float(env_scale)
        self.edit_t = int(edit_t)
        self.reference_env = tuple(float(v) for v in reference_env)
        if len(self.reference_env) != 3:
            raise SimdiffError(f"reference_env must be 3 numbers (g_z, w_x, w_y), got {len(self.reference_env)}")

    def __call__(self, x: Tensor, timesteps: Tensor, cond: Condition) -> Tensor:
        """x: (B, T, F), timesteps: (B,) → guided x̂₀ (B, T, F)."""
        if cond.env is None:
            if self.env_scale != 1.0:
                raise SimdiffError("environment guidance needs a SimDiff model with a continuous Sim Encoder "
                                   "(φ as numbers)")
            return self._text_guided(x, timesteps, cond)[1]
        phi = torch.tensor(self.reference_env, dtype=cond.env.dtype, device=cond.env.device)
        edited = cond.env[:, 0] != phi[0]
        if int(timesteps.max()) > self.edit_t:
            edited = torch.zeros_like(edited)
        keep = (~edited).nonzero().flatten()
        guided = torch.empty_like(x)
        if keep.numel():  # Earth's gravity: the backbone, plus the adapters' answer to the wind
            guided[keep] = self._earth(x[keep], timesteps[keep], cond.select(keep), phi)
        if bool(edited.any()):  # another gravity, at and below edit_t: the adapters under φ
            e = edited.nonzero().flatten()
            xr, tr, ce = x[e], timesteps[e], cond.select(e)
            if self.env_scale == 1.0:
                guided[e] = self._text_guided(xr, tr, ce)[1]
            else:
                guided[e] = self._env_guided(xr, tr, ce, replace(ce, env=phi.expand(len(e), 3).clone()))
        return guided

    def _env_guided(self, x: Tensor, timesteps: Tensor, cond: Condition, at_ref: Condition) -> Tensor:
        """G_α(c, φ) + (s_e − 1)·(x₀(c, φ) − x₀(c, φ_ref)) (B, T, F); ``at_ref``: ``cond`` at φ_ref. Batched, the
        reference rows ride in the text passes' forward (3B rows, 2B without text guidance)."""
        if not self.batched:
            cond_out, g = self._text_guided(x, timesteps, cond)
            return g + (self.env_scale - 1.0) * (cond_out - self.denoiser(x, timesteps, at_ref))
        text = self.scale != 1.0 and int(timesteps.max()) >= self.min_t
        first = cond.with_guidance_pair() if text else cond
        k = 3 if text else 2
        # one forward instead of two: a 6 s motion at g −1.6, batch 1, samples in 0.83 s instead of 0.91 s (7 seeds)
        parts = self.denoiser(torch.cat([x] * k), torch.cat([timesteps] * k), first.stacked(at_ref)).chunk(k)
        cond_out, ref = parts[0], parts[-1]
        g = self._cfg(cond_out, parts[1]) if text else cond_out
        return g + (self.env_scale - 1.0) * (cond_out - ref)

    def _text_guided(self, x: Tensor, timesteps: Tensor, cond: Condition) -> tuple[Tensor, Tensor]:
        """(x₀(c) (B, T, F), its classifier-free guided x̃₀ (B, T, F)) under ``cond``'s φ and α."""
        if self.scale == 1.0 or int(timesteps.max()) < self.min_t:
            out = self.denoiser(x, timesteps, cond)
            return out, out
        if self.batched:
            out = self.denoiser(torch.cat([x, x]), torch.cat([timesteps, timesteps]), cond.with_guidance_pair())
            cond_out, uncond_out = out.chunk(2)
        else:
            cond_out = self.denoiser(x, timesteps, cond)
            uncond_out = self.denoiser(x, timesteps, cond.unconditional())
        return cond_out, self._cfg(cond_out, uncond_out)

    def _cfg(self, cond_out: Tensor, uncond_out: Tensor) -> Tensor:
        """x₀(∅) + s·(x₀(c) − x₀(∅)) (B, T, F)."""
        return uncond_out + self.scale * (cond_out - uncond_out)

    def _earth(self, x: Tensor, timesteps: Tensor, cond: Condition, phi: Tensor) -> Tensor:
        """G(c) (the backbone's guided x̃₀) for every row, plus the adapters' answer to φ against φ_ref on the rows
        with wind under Earth's gravity: G_α(c, φ) − G_α(c, φ_ref) + (s_e − 1)·(x₀(c, φ) − x₀(c, φ_ref)). Rows off
        Earth's gravity (here above ``edit_t``) get G(c) alone. ``phi``: (3,) φ_ref."""
        assert cond.env is not None
        backbone = replace(cond, alpha=0.0, env=phi.expand_as(cond.env).clone())
        guided = self._text_guided(x, timesteps, backbone)[1]
        rows = ((cond.env != phi).any(dim=-1) & (cond.env[:, 0] == phi[0])).nonzero().flatten()
        if not rows.numel():
            return guided
        guided = guided.clone()
        sub = cond.select(rows)
        ref = replace(sub, env=phi.expand(len(rows), 3).clone())
        xr, tr = x[rows], timesteps[rows]
        cond_out, text_out = self._text_guided(torch.cat([xr, xr]), torch.cat([tr, tr]), sub.stacked(ref))
        (c_phi, c_ref), (g_phi, g_ref) = cond_out.chunk(2), text_out.chunk(2)
        guided[rows] += (g_phi - g_ref) + (self.env_scale - 1.0) * (c_phi - c_ref)
        return guided
