"""Guidance on the x₀ prediction.

* Classifier-free guidance on the text: x̃₀ = x₀(∅, φ) + s·(x₀(c, φ) − x₀(∅, φ)).
* Environment guidance (continuous SimDiff models): x̃₀ += (s_e − 1)·(x₀(c, φ) − x₀(c, φ_ref)), the
  adapters' answer to φ against the reference environment (Earth, no wind) pushed ``s_e`` times as far.
  Rows whose φ equals the reference are left exactly as without it.
* Anchor (continuous SimDiff models): ``"adapters"`` (the default) guides the text with the adapters on, as above;
  ``"backbone"`` guides the text with the backbone alone (α 0) and adds the adapters' answer to φ against the
  reference: x̃₀ = x₀⁰(∅) + s·(x₀⁰(c) − x₀⁰(∅)) + s_e·(x₀(c, φ) − x₀(c, φ_ref)). At the reference φ it is exactly
  the backbone; elsewhere only the change of φ, not the adapters' answer to Earth itself, moves the motion.
  ``anchor_alpha`` a > 0 runs that text guidance with the adapters at strength a instead (x₀⁰ → x₀ᵃ, the environment
  term still at the condition's α): at the reference φ it is exactly the adapters anchor at α = a (session 54: the
  adapters' answer to Earth costs FID and jumps, their answer to φ is what the environment needs).
  ``"reference"`` runs the text guidance at the reference φ with the adapters at ``anchor_alpha`` a and adds the
  adapters anchor's own answer to φ (its guided output at φ minus at φ_ref, both at the condition's α):
  x̃₀ = G_a(c, φ_ref) + G_α(c, φ) − G_α(c, φ_ref), G being the adapters anchor's x̃₀ above. At the reference φ it is
  exactly the adapters anchor at α = a; elsewhere the change of φ moves the motion exactly as far as the adapters
  anchor at α would, text guidance included (session 55: the backbone anchor's push, outside the text guidance,
  cost text fidelity under low gravity). Costs one 2B forward plus one 4K forward over the K rows off φ_ref.
* ``"edit"``: the rows whose gravity is off φ_ref's follow the reference anchor at φ_ref (``anchor_alpha`` a: exactly
  the backbone at a = 0) at the steps whose timestep is above ``edit_t`` T_e, and run the adapters anchor at their φ at
  and below it (x̃₀ = G_α(c, φ), environment guidance included). Such a sample is its Earth sample of the same noise
  until T_e, re-played under φ from there: what adapters trained on crossed twins (``TrainConfig.cross_twins``: the
  other twin's x_t, one's own target) learn to do. Every other row is exactly the reference anchor's: Earth's, and
  under Earth's gravity with wind the reference anchor's answer to the wind at every step (since session 71: the
  adapters anchor alone at α 1 pushed session 70's walks 1–2 m towards −y whatever the wind, while the reference
  anchor's answer to wind cancels what the adapters do at φ_ref). Costs one 2B forward per step, plus one 4W forward
  over the W wind-only rows, plus one K forward over the K edited rows at T_e and below when s_e ≠ 1.
* ``anchor_t_max`` T: the backbone or reference anchor runs only at the steps whose timestep is ≤ T, the adapters
  anchor at the earlier ones (session 55: what the text asks for is settled by the early, noisy steps, the adapters'
  answer to Earth, a matter of detail, by the late ones).
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
"""φ_ref of environment guidance: Earth's gravity (m/s², along z) and no wind (N)."""

ANCHORS: tuple[str, ...] = ("adapters", "backbone", "reference", "edit")
"""What the text guidance runs on: the network with its adapters at α, the backbone alone, the network at the
reference φ, or that until ``edit_t`` and the adapters at φ after it (see the module)."""

ALPHA_ANCHORS: tuple[str, ...] = ("backbone", "reference", "edit")
"""The anchors that take an ``anchor_alpha``."""

T_MAX_ANCHORS: tuple[str, ...] = ("backbone", "reference")
"""The anchors that take an ``anchor_t_max``."""

DEFAULT_EDIT_T: int = 800
"""The edit anchor's last timestep at the reference φ unless told (of the two that session 70 screened, 600 and 800,
the one with the larger answer to low gravity; neither passed that screen)."""


def _whole_timestep(name: str, value: int | float) -> int:
    """``value`` as an int in [0, 999], else a one-line :class:`SimdiffError` naming ``name``."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or value != int(value) or not 0 <= value <= 999:
        raise SimdiffError(f"{name} must be a whole timestep in 0..999, got {value}")
    return int(value)


def check_anchor_t_max(value: int | None, anchor: str) -> int | None:
    """``value`` as an int in [0, 999] that ``anchor`` can use (None: every step, any anchor), else one
    :class:`SimdiffError` line naming it."""
    if value is None:
        return None
    value = _whole_timestep("anchor t max", value)
    if anchor not in T_MAX_ANCHORS:
        raise SimdiffError(f"anchor t max {int(value)} needs the backbone or reference anchor (--anchor backbone or "
                           f"reference), not {anchor!r}")
    return int(value)


def check_edit_t(value: int | None, anchor: str) -> int | None:
    """``value`` as an int in [0, 999] when ``anchor`` is ``"edit"`` (None there: :data:`DEFAULT_EDIT_T`); None for
    the other anchors, which take none (a value given with them is one :class:`SimdiffError` line naming it)."""
    if value is None:
        return DEFAULT_EDIT_T if anchor == "edit" else None
    value = _whole_timestep("edit t", value)
    if anchor != "edit":
        raise SimdiffError(f"edit t {int(value)} needs the edit anchor (--anchor edit), not {anchor!r}")
    return int(value)


def check_anchor_alpha(value: float, anchor: str) -> float:
    """``value`` as a float when it is a finite number ≥ 0 that ``anchor`` can use (any anchor takes 0), else one
    :class:`SimdiffError` line naming it."""
    value = float(value)
    if not (0.0 <= value < float("inf")):
        raise SimdiffError(f"anchor alpha must be a finite number ≥ 0, got {value}")
    if value and anchor not in ALPHA_ANCHORS:
        raise SimdiffError(f"anchor alpha {value} needs the backbone, reference or edit anchor (--anchor backbone, "
                           f"reference or edit), not {anchor!r}")
    return value


class GuidedDenoiser:
    """Wrap a denoiser with classifier-free guidance.

    Args:
        denoiser: the network (MDMBackbone or SimDiffNet, or anything with the same call).
        scale: s; 1 disables guidance (one conditional pass).
        batched: run the conditional and unconditional passes as one 2B forward (default)
            instead of two B forwards. The text is dropped in the second half only; φ/α are kept.
        env_scale: s_e of environment guidance; 1 disables it. Needs ``cond.env`` (a continuous
            Sim Encoder); costs one more conditional forward over the rows whose φ is not ``reference_env``
            (a separate one: the other rows are computed bit for bit as without it).
        reference_env: φ_ref = (g_z m/s², w_x N, w_y N).
        anchor: ``"adapters"``, ``"backbone"`` or ``"reference"`` (see the module); the last two need ``cond.env``.
            ``"backbone"`` costs one 2K forward over the K rows whose φ is not ``reference_env`` (φ and φ_ref with
            the adapters at α), ``"reference"`` one 4K forward over them (both with and without the text).
        anchor_alpha: adapter strength a of the backbone or reference anchor's text guidance (0: the backbone
            alone); only with ``anchor="backbone"`` or ``"reference"``.
        anchor_t_max: the backbone or reference anchor only at timesteps ≤ this (0..999), the adapters anchor
            above it (None: every step).
        edit_t: the edit anchor's last timestep at φ_ref (0..999; None: :data:`DEFAULT_EDIT_T`); only with
            ``anchor="edit"``.
    """

    def __init__(self, denoiser: Denoiser, scale: float = 2.5, batched: bool = True, env_scale: float = 1.0,
                 reference_env: Sequence[float] = REFERENCE_ENV, anchor: str = "adapters",
                 anchor_alpha: float = 0.0, anchor_t_max: int | None = None, edit_t: int | None = None) -> None:
        self.denoiser = denoiser
        self.scale = float(scale)
        self.batched = batched
        self.env_scale = float(env_scale)
        self.reference_env = tuple(float(v) for v in reference_env)
        if len(self.reference_env) != 3:
            raise SimdiffError(f"reference_env must be 3 numbers (g_z, w_x, w_y), got {len(self.reference_env)}")
        if anchor not in ANCHORS:
            raise SimdiffError(f"unknown guidance anchor {anchor!r}; choose one of {', '.join(ANCHORS)}")
        self.anchor = anchor
        self.anchor_alpha = check_anchor_alpha(anchor_alpha, anchor)
        self.anchor_t_max = check_anchor_t_max(anchor_t_max, anchor)
        self.edit_t = check_edit_t(edit_t, anchor)

    def __call__(self, x: Tensor, timesteps: Tensor, cond: Condition) -> Tensor:
        """x: (B, T, F), timesteps: (B,) → guided x̂₀ (B, T, F)."""
        anchor = self.anchor
        if self.anchor_t_max is not None and int(timesteps.max()) > self.anchor_t_max:
            anchor = "adapters"  # an early step
        if anchor == "edit":
            return self._edit_anchor(x, timesteps, cond)
        rows, ref = self._plan(cond, anchor)
        if anchor == "reference":
            return self._reference_anchor(x, timesteps, cond, rows, ref)
        text_cond = cond if anchor == "adapters" else replace(cond, alpha=self.anchor_alpha)
        cond_out, guided = self._text_guided(x, timesteps, text_cond)
        if rows is None or ref is None:  # nothing off the reference φ
            return guided
        # passes of their own, so that the rows above are computed exactly as without environment guidance
        guided = guided.clone()
        if anchor == "adapters":
            ref_out = self.denoiser(x[rows], timesteps[rows], ref)
            guided[rows] += (self.env_scale - 1.0) * (cond_out[rows] - ref_out)
            return guided
        xr, tr = x[rows], timesteps[rows]
        phi_out, ref_out = self.denoiser(torch.cat([xr, xr]), torch.cat([tr, tr]), cond.select(rows).stacked(ref)).chunk(2)
        guided[rows] += self.env_scale * (phi_out - ref_out)
        return guided

    def _text_guided(self, x: Tensor, timesteps: Tensor, cond: Condition) -> tuple[Tensor, Tensor]:
        """(x₀(c) (B, T, F), its classifier-free guided x̃₀ (B, T, F)) under ``cond``'s φ and α."""
        if self.scale == 1.0:
            out = self.denoiser(x, timesteps, cond)
            return out, out
        if self.batched:
            out = self.denoiser(torch.cat([x, x]), torch.cat([timesteps, timesteps]), cond.with_guidance_pair())
            cond_out, uncond_out = out.chunk(2)
        else:
            cond_out = self.denoiser(x, timesteps, cond)
            uncond_out = self.denoiser(x, timesteps, cond.unconditional())
        return cond_out, uncond_out + self.scale * (cond_out - uncond_out)

    def _reference_anchor(self, x: Tensor, timesteps: Tensor, cond: Condition, rows: Tensor | None,
                          ref: Condition | None) -> Tensor:
        """G_a(c, φ_ref) for every row, plus G_α(c, φ) − G_α(c, φ_ref) on the rows off φ_ref (see the module)."""
        assert cond.env is not None  # _plan checked it
        phi = torch.tensor(self.reference_env, dtype=cond.env.dtype, device=cond.env.device)
        _, guided = self._text_guided(x, timesteps, replace(cond, alpha=self.anchor_alpha,
                                                            env=phi.expand_as(cond.env).clone()))
        if rows is None or ref is None:
            return guided
        guided = guided.clone()
        xr, tr = x[rows], timesteps[rows]
        cond_out, text_out = self._text_guided(torch.cat([xr, xr]), torch.cat([tr, tr]), cond.select(rows).stacked(ref))
        (c_phi, c_ref), (g_phi, g_ref) = cond_out.chunk(2), text_out.chunk(2)
        guided[rows] += (g_phi - g_ref) + (self.env_scale - 1.0) * (c_phi - c_ref)
        return guided

    def _edit_anchor(self, x: Tensor, timesteps: Tensor, cond: Condition) -> Tensor:
        """The reference anchor (its answer to φ at α) for every row but those whose gravity is off φ_ref's at and
        below ``edit_t``: the adapters anchor's x̃₀ at φ there (see the module)."""
        rows, _ = self._plan(cond, "edit")
        assert cond.env is not None  # _plan checked it
        assert self.edit_t is not None
        phi = torch.tensor(self.reference_env, dtype=cond.env.dtype, device=cond.env.device)
        edited = cond.env[:, 0] != phi[0]
        if rows is None or int(timesteps.max()) > self.edit_t:
            edited = torch.zeros_like(edited)
        keep = (~edited).nonzero().flatten()
        guided = torch.empty_like(x)
        if keep.numel():  # Earth and wind alone: the reference anchor, its answer to the wind included
            sub = cond.select(keep)
            wind = (sub.env != phi).any(dim=-1) & (sub.env[:, 0] == phi[0])  # type: ignore[index]
            w = wind.nonzero().flatten()
            w_ref = replace(sub.select(w), env=phi.expand(len(w), 3).clone()) if w.numel() else None
            guided[keep] = self._reference_anchor(x[keep], timesteps[keep], sub, w if w.numel() else None, w_ref)
        if bool(edited.any()):
            e = edited.nonzero().flatten()
            xr, tr, ce = x[e], timesteps[e], cond.select(e)
            cond_out, g = self._text_guided(xr, tr, ce)
            if self.env_scale != 1.0:
                at_ref = replace(ce, env=phi.expand(len(e), 3).clone())
                g = g + (self.env_scale - 1.0) * (cond_out - self.denoiser(xr, tr, at_ref))
            guided[e] = g
        return guided

    def _plan(self, cond: Condition, anchor: str) -> tuple[Tensor | None, Condition | None]:
        """((K,) indices of the rows environment guidance changes, their condition with φ set to the reference), or
        (None, None) when it changes none (a few small tensor operations per step, next to a network pass)."""
        if self.env_scale == 1.0 and self.anchor == "adapters":
            return None, None
        if cond.env is None:
            what = "environment guidance" if self.anchor == "adapters" else f"the {self.anchor} anchor"
            raise SimdiffError(f"{what} needs a SimDiff model with a continuous Sim Encoder (φ as numbers)")
        if self.env_scale == 1.0 and anchor == "adapters":  # an early step of anchor_t_max
            return None, None
        phi = torch.tensor(self.reference_env, dtype=cond.env.dtype, device=cond.env.device)
        rows = torch.nonzero((cond.env != phi).any(dim=-1)).flatten()
        if not rows.numel():
            return None, None
        sub = cond.select(rows)
        return rows, replace(sub, env=phi.expand_as(sub.env).clone())  # type: ignore[arg-type]
