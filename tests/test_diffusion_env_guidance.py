"""How φ enters the denoising of continuous-φ SimDiff models (:mod:`simdiff.diffusion.guidance`): Earth rows are the
backbone's CFG, wind rows add the adapters' guided answer to the wind, rows off Earth's gravity follow Earth until
``edit_t`` and then the adapters at φ with environment guidance."""

from __future__ import annotations

import pytest
import torch

from simdiff.diffusion.config import SamplingConfig
from simdiff.diffusion.guidance import REFERENCE_ENV, GuidedDenoiser
from simdiff.diffusion.sampling import sample
from simdiff.errors import SimdiffError
from simdiff.model import Condition, MDMBackbone, SimConfig, SimDiffNet, backbone_preset

ENVS = torch.tensor([[-1.6, 0.0, 0.0], [-9.81, 0.0, 0.0], [-9.81, 10.0, 0.0]])
"""Rows: low gravity, Earth, wind under Earth's gravity."""


def simdiff_net() -> SimDiffNet:
    torch.manual_seed(0)
    sd = SimDiffNet(backbone_preset("tiny"), SimConfig()).eval()
    for a in sd.adapters:  # zero-initialised adapters would make φ invisible
        torch.nn.init.normal_(a.up.weight, std=0.3)
    return sd


def cond(alpha: float | torch.Tensor = 0.5) -> Condition:
    return Condition(text=torch.randn(3, 384, generator=torch.Generator().manual_seed(2)), env=ENVS.clone(), alpha=alpha)


def earth(c: Condition, alpha: float | None = None) -> Condition:
    return Condition(text=c.text, env=torch.tensor([REFERENCE_ENV] * c.batch_size),
                     alpha=c.alpha if alpha is None else alpha)


def cfg(net, x: torch.Tensor, t: torch.Tensor, c: Condition, s: float = 2.5) -> torch.Tensor:
    """x₀(∅) + s·(x₀(c) − x₀(∅)), two plain passes."""
    uncond = net(x, t, c.unconditional())
    return uncond + s * (net(x, t, c) - uncond)


@pytest.mark.parametrize("env_scale", [1.0, 3.0])
def test_each_row_follows_the_module_formulas(env_scale: float) -> None:
    sd, c = simdiff_net(), cond()
    x = torch.randn(3, 8, 263, generator=torch.Generator().manual_seed(6))
    guided = GuidedDenoiser(sd, 2.5, env_scale=env_scale, edit_t=600)
    with torch.no_grad():
        for step in (999, 601, 600, 20):
            t = torch.full((3,), step)
            out = guided(x, t, c)
            backbone = cfg(sd, x, t, earth(c, alpha=0.0))
            wind = backbone + cfg(sd, x, t, c) - cfg(sd, x, t, earth(c)) \
                + (env_scale - 1.0) * (sd(x, t, c) - sd(x, t, earth(c)))
            phi = cfg(sd, x, t, c) + (env_scale - 1.0) * (sd(x, t, c) - sd(x, t, earth(c)))
            assert torch.allclose(out[1], backbone[1], atol=1e-5), step  # Earth: the backbone alone
            assert torch.allclose(out[2], wind[2], atol=1e-5), step  # wind: its answer added at every step
            assert torch.allclose(out[0], (backbone if step > 600 else phi)[0], atol=1e-5), step
            assert (phi[0] - backbone[0]).abs().max() > 1e-3


def test_a_row_with_gravity_and_wind_is_edited() -> None:
    sd = simdiff_net()
    c = cond()
    c.env = torch.tensor([[-1.6, 0.0, 10.0], [-9.81, 0.0, -10.0], [-9.81, 0.0, 0.0]])
    x, t = torch.randn(3, 8, 263, generator=torch.Generator().manual_seed(7)), torch.full((3,), 100)
    with torch.no_grad():
        out = GuidedDenoiser(sd, 2.5, edit_t=500)(x, t, c)
        assert torch.allclose(out[0], cfg(sd, x, t, c)[0], atol=1e-5)


def test_one_2b_forward_per_step_plus_the_wind_and_edited_rows() -> None:
    sd, sizes = simdiff_net(), []

    def counting(x: torch.Tensor, t: torch.Tensor, c: Condition) -> torch.Tensor:
        sizes.append(x.shape[0])
        return sd(x, t, c)

    x = torch.randn(3, 8, 263)
    with torch.no_grad():
        GuidedDenoiser(counting, 2.5, edit_t=500)(x, torch.full((3,), 900), cond())
        GuidedDenoiser(counting, 2.5, edit_t=500)(x, torch.full((3,), 300), cond())
        # early: one batch at φ_ref and the wind row's φ / φ_ref pair; late: the same over the Earth and wind rows,
        # then the low-g row at its φ
        assert sizes == [6, 4, 4, 4, 2]
        sizes.clear()
        GuidedDenoiser(counting, 2.5, env_scale=2.0, edit_t=500)(x, torch.full((3,), 300), cond())
        assert sizes == [4, 4, 3]  # s_e ≠ 1: the edited row at φ_ref rides in its text passes' forward
        sizes.clear()
        GuidedDenoiser(counting, 2.5, env_scale=2.0, edit_t=500, min_t=400)(x, torch.full((3,), 300), cond())
        assert sizes == [2, 2, 2]  # below min_t no text guidance: conditional rows only, the reference beside them


def test_per_row_alpha_and_text_drop_are_kept() -> None:
    sd = simdiff_net()
    c = cond(alpha=torch.tensor([0.2, 0.5, 1.0]))
    c.uncond = torch.tensor([False, False, True])
    x, t = torch.randn(3, 8, 263), torch.tensor([300, 300, 300])
    with torch.no_grad():
        batched = GuidedDenoiser(sd, 2.5, True, env_scale=4.0)(x, t, c)
        unbatched = GuidedDenoiser(sd, 2.5, False, env_scale=4.0)(x, t, c)
    assert torch.allclose(batched, unbatched, atol=1e-4)


def test_without_phi_it_is_plain_cfg_and_env_guidance_needs_a_continuous_env() -> None:
    torch.manual_seed(0)
    backbone = MDMBackbone(backbone_preset("tiny")).eval()
    c = Condition(text=torch.randn(2, 384))
    x, t = torch.randn(2, 8, 263), torch.full((2,), 400)
    with torch.no_grad():
        assert torch.allclose(GuidedDenoiser(backbone, 2.5)(x, t, c), cfg(backbone, x, t, c), atol=1e-5)
    with pytest.raises(SimdiffError, match="continuous Sim Encoder"):
        GuidedDenoiser(backbone, 2.5, env_scale=2.0)(x, t, c)
    with pytest.raises(SimdiffError, match="3 numbers"):
        GuidedDenoiser(backbone, 2.5, env_scale=2.0, reference_env=(0.0, 1.0))


def test_sampling_keeps_earth_rows_on_the_backbone() -> None:
    sd, c = simdiff_net(), cond()
    config = SamplingConfig(steps=6, edit_t=500, env_guidance=2.0)
    edited = sample(sd, config, c, 10, generator=torch.Generator().manual_seed(0))
    alone = sample(sd, config, earth(c, alpha=0.0), 10, generator=torch.Generator().manual_seed(0))
    assert torch.allclose(edited[1], alone[1], atol=1e-5)
    assert not torch.allclose(edited[0], alone[0], atol=1e-3)


def test_condition_select_picks_rows() -> None:
    a = cond(alpha=torch.tensor([1.0, 0.0, 0.5]))
    picked = a.select(torch.tensor([2, 0]))
    assert torch.equal(picked.env, ENVS[[2, 0]]) and torch.equal(picked.text, a.text[[2, 0]])
    assert picked.alpha.tolist() == [0.5, 1.0] and picked.uncond is None


def test_condition_stacked() -> None:
    a, b = cond(alpha=0.5), cond(alpha=torch.tensor([1.0, 0.0, 0.5]))
    same = a.stacked(a)
    assert same.batch_size == 6 and same.alpha == 0.5 and same.uncond is None
    assert torch.equal(same.env, torch.cat([ENVS, ENVS]))
    mixed = a.stacked(b)
    assert mixed.alpha.tolist() == [0.5, 0.5, 0.5, 1.0, 0.0, 0.5]
    b.uncond = torch.tensor([True, False, False])
    assert a.stacked(b).uncond.tolist() == [False, False, False, True, False, False]
    with pytest.raises(ValueError, match="env"):
        a.stacked(Condition(text=a.text))


def test_below_guidance_min_t_every_row_takes_its_conditional_pass_alone() -> None:
    sd, sizes = simdiff_net(), []

    def counting(x: torch.Tensor, t: torch.Tensor, c: Condition) -> torch.Tensor:
        sizes.append(x.shape[0])
        return sd(x, t, c)

    x, c = torch.randn(3, 8, 263), cond()
    with torch.no_grad():
        above = GuidedDenoiser(counting, 2.5, edit_t=500, min_t=300)(x, torch.full((3,), 300), c)
        assert sizes == [4, 4, 2] and torch.allclose(above, GuidedDenoiser(sd, 2.5, edit_t=500)(x, torch.full((3,), 300), c))
        sizes.clear()
        below = GuidedDenoiser(counting, 2.5, edit_t=500, min_t=301)(x, torch.full((3,), 300), c)
        assert sizes == [2, 2, 1]  # half the rows: the unconditional passes are gone
        t = torch.full((3,), 300)
        assert torch.allclose(below[1], sd(x[1:2], t[:1], earth(c.select(torch.tensor([1])), alpha=0.0))[0], atol=1e-5)
        assert torch.allclose(below[0], sd(x[:1], t[:1], c.select(torch.tensor([0])))[0], atol=1e-5)
