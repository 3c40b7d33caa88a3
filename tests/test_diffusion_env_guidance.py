"""Environment guidance: x̃₀ = CFG(φ) + (s_e − 1)·(x₀(c, φ) − x₀(c, φ_ref)); Earth rows untouched. And the backbone
anchor: x̃₀ = CFG of the backbone (α 0) + s_e·(x₀(c, φ, α) − x₀(c, φ_ref, α))."""

from __future__ import annotations

import pytest
import torch

from simdiff.diffusion import GuidedDenoiser, make_scheduler, sample
from simdiff.diffusion.guidance import REFERENCE_ENV
from simdiff.errors import SimdiffError
from simdiff.model import Condition, MDMBackbone, SimConfig, SimDiffNet, backbone_preset

ENVS = torch.tensor([[-1.6, 0.0, 0.0], [-9.81, 0.0, 0.0], [-9.81, 10.0, 0.0]])


def simdiff_net() -> SimDiffNet:
    torch.manual_seed(0)
    sd = SimDiffNet(backbone_preset("tiny"), SimConfig()).eval()
    for a in sd.adapters:  # zero-initialised adapters would make φ invisible
        torch.nn.init.normal_(a.up.weight, std=0.3)
    return sd


def cond(alpha: float | torch.Tensor = 0.5) -> Condition:
    return Condition(text=torch.randn(3, 384, generator=torch.Generator().manual_seed(2)), env=ENVS.clone(), alpha=alpha)


def earth(c: Condition) -> Condition:
    return Condition(text=c.text, env=torch.tensor([REFERENCE_ENV] * c.batch_size), alpha=c.alpha)


@pytest.mark.parametrize("batched", [True, False])
@pytest.mark.parametrize("scale", [2.5, 1.0])
def test_formula_and_reference_rows_unchanged(batched: bool, scale: float) -> None:
    sd, c = simdiff_net(), cond()
    x, t = torch.randn(3, 8, 263, generator=torch.Generator().manual_seed(1)), torch.tensor([900, 500, 20])
    with torch.no_grad():
        cfg = GuidedDenoiser(sd, scale, batched)(x, t, c)
        out = GuidedDenoiser(sd, scale, batched, env_scale=3.0)(x, t, c)
        push = sd(x, t, c) - sd(x, t, earth(c))
    expected = cfg + 2.0 * push
    assert torch.allclose(out, expected, atol=1e-4)
    assert torch.equal(out[1], cfg[1])  # φ = φ_ref: bit-identical
    assert (out[0] - cfg[0]).abs().max() > 1e-3 and (out[2] - cfg[2]).abs().max() > 1e-3
    with torch.no_grad():  # s_e = 1 is the plain guided denoiser
        assert torch.equal(GuidedDenoiser(sd, scale, batched, env_scale=1.0)(x, t, c), cfg)


def test_one_more_forward_over_the_changed_rows_only() -> None:
    sd, c = simdiff_net(), cond()
    calls: list[int] = []

    def counting(x, t, cc):
        calls.append(x.shape[0])
        return sd(x, t, cc)

    x, t = torch.randn(3, 8, 263), torch.zeros(3, dtype=torch.long)
    with torch.no_grad():
        GuidedDenoiser(counting, 2.5, env_scale=2.0)(x, t, c)
        assert calls == [6, 2]  # the CFG pair as before, then the two rows off Earth
        calls.clear()
        GuidedDenoiser(counting, 2.5, env_scale=2.0)(x, t, earth(c))  # nothing off Earth: no extra pass
        assert calls == [6]


def test_per_row_alpha_and_text_drop_are_kept() -> None:
    sd = simdiff_net()
    c = cond(alpha=torch.tensor([0.2, 0.5, 1.0]))
    c.uncond = torch.tensor([False, False, True])
    x, t = torch.randn(3, 8, 263), torch.tensor([300, 300, 300])
    with torch.no_grad():
        batched = GuidedDenoiser(sd, 2.5, True, env_scale=4.0)(x, t, c)
        unbatched = GuidedDenoiser(sd, 2.5, False, env_scale=4.0)(x, t, c)
    assert torch.allclose(batched, unbatched, atol=1e-4)


def test_needs_a_continuous_env() -> None:
    torch.manual_seed(0)
    backbone = MDMBackbone(backbone_preset("tiny")).eval()
    c = Condition(text=torch.randn(2, 384))
    with pytest.raises(SimdiffError, match="continuous Sim Encoder"):
        GuidedDenoiser(backbone, 2.5, env_scale=2.0)(torch.randn(2, 8, 263), torch.zeros(2, dtype=torch.long), c)
    with pytest.raises(SimdiffError, match="3 numbers"):
        GuidedDenoiser(backbone, 2.5, env_scale=2.0, reference_env=(0.0, 1.0))


def test_sampling_keeps_earth_samples_and_moves_the_others() -> None:
    sd, c = simdiff_net(), cond()
    s = make_scheduler("ddim", 8)
    plain = sample(sd, s, c, 10, generator=torch.Generator().manual_seed(0))
    guided = sample(sd, s, c, 10, generator=torch.Generator().manual_seed(0), env_guidance=3.0)
    assert torch.equal(plain[1], guided[1])
    assert not torch.allclose(plain[0], guided[0], atol=1e-3)


def test_condition_select_picks_rows() -> None:
    a = cond(alpha=torch.tensor([1.0, 0.0, 0.5]))
    picked = a.select(torch.tensor([2, 0]))
    assert torch.equal(picked.env, ENVS[[2, 0]]) and torch.equal(picked.text, a.text[[2, 0]])
    assert picked.alpha.tolist() == [0.5, 1.0] and picked.uncond is None


# --- the backbone anchor -----------------------------------------------------------------------------------

def with_env(c: Condition, env: torch.Tensor, alpha: float | torch.Tensor | None = None) -> Condition:
    return Condition(text=c.text, env=env, alpha=c.alpha if alpha is None else alpha)


@pytest.mark.parametrize("batched", [True, False])
@pytest.mark.parametrize("scale,env_scale", [(2.5, 2.0), (1.0, 1.0), (2.5, 0.0)])
def test_formula_and_reference_rows_are_the_backbone(batched: bool, scale: float, env_scale: float) -> None:
    sd, c = simdiff_net(), cond()
    x, t = torch.randn(3, 8, 263, generator=torch.Generator().manual_seed(1)), torch.tensor([900, 500, 20])
    earth = torch.tensor([REFERENCE_ENV] * 3)
    with torch.no_grad():
        out = GuidedDenoiser(sd, scale, batched, env_scale=env_scale, anchor="backbone")(x, t, c)
        backbone = GuidedDenoiser(sd, scale, batched)(x, t, with_env(c, ENVS, alpha=0.0))
        push = sd(x, t, c) - sd(x, t, with_env(c, earth))
        adapters = GuidedDenoiser(sd, scale, batched)(x, t, c)
    assert torch.allclose(out, backbone + env_scale * push, atol=1e-4)
    assert torch.equal(out[1], backbone[1])  # φ = φ_ref: the backbone alone, bit for bit
    assert (out[1] - adapters[1]).abs().max() > 1e-3  # ... which is not what the adapters anchor gives
    if env_scale:
        assert (out[0] - backbone[0]).abs().max() > 1e-3 and (out[2] - backbone[2]).abs().max() > 1e-3


@pytest.mark.parametrize("a", [0.25, 0.5])
def test_anchor_alpha_runs_the_text_guidance_at_a_and_the_push_at_alpha(a: float) -> None:
    sd, c = simdiff_net(), cond()  # α 0.5 in the condition
    x, t = torch.randn(3, 8, 263, generator=torch.Generator().manual_seed(2)), torch.tensor([900, 500, 20])
    earth = torch.tensor([REFERENCE_ENV] * 3)
    with torch.no_grad():
        out = GuidedDenoiser(sd, 2.5, env_scale=4.0, anchor="backbone", anchor_alpha=a)(x, t, c)
        text = GuidedDenoiser(sd, 2.5)(x, t, with_env(c, ENVS, alpha=a))  # the adapters anchor at α = a
        push = sd(x, t, c) - sd(x, t, with_env(c, earth))  # at the condition's α
        plain = GuidedDenoiser(sd, 2.5)(x, t, c)
    assert torch.allclose(out, text + 4.0 * push, atol=1e-4)
    assert torch.equal(out[1], text[1])  # φ = φ_ref: exactly the adapters anchor at α = a
    if a == 0.5:  # a equal to α: at Earth the plain adapters anchor, bit for bit
        assert torch.equal(out[1], plain[1])


def test_anchor_alpha_is_checked_in_one_line() -> None:
    for bad in (-0.1, float("nan"), float("inf")):
        with pytest.raises(SimdiffError, match="anchor alpha must be a finite number ≥ 0"):
            GuidedDenoiser(simdiff_net(), 2.5, anchor="backbone", anchor_alpha=bad)
    with pytest.raises(SimdiffError, match="anchor alpha 0.25 needs the backbone, reference or edit anchor"):
        GuidedDenoiser(simdiff_net(), 2.5, anchor="adapters", anchor_alpha=0.25)


# --- the reference anchor ----------------------------------------------------------------------------------

@pytest.mark.parametrize("batched", [True, False])
@pytest.mark.parametrize("a", [0.25, 0.0])
def test_reference_anchor_is_the_text_guidance_at_earth_plus_the_adapters_anchors_answer(batched: bool, a: float) -> None:
    sd, c = simdiff_net(), cond()  # α 0.5 in the condition
    x, t = torch.randn(3, 8, 263, generator=torch.Generator().manual_seed(3)), torch.tensor([900, 500, 20])
    with torch.no_grad():
        out = GuidedDenoiser(sd, 2.5, batched, env_scale=4.0, anchor="reference", anchor_alpha=a)(x, t, c)
        base = GuidedDenoiser(sd, 2.5, batched)(x, t, earth(with_env(c, ENVS, alpha=a)))  # adapters anchor, Earth, α a
        at_phi = GuidedDenoiser(sd, 2.5, batched, env_scale=4.0)(x, t, c)  # the adapters anchor at φ and α
        at_ref = GuidedDenoiser(sd, 2.5, batched)(x, t, earth(c))  # ... at φ_ref
    assert torch.allclose(out, base + at_phi - at_ref, atol=1e-4)
    assert torch.equal(out[1], base[1])  # φ = φ_ref: exactly the adapters anchor at α = a
    assert (out[0] - base[0]).abs().max() > 1e-3 and (out[2] - base[2]).abs().max() > 1e-3


def test_reference_anchor_at_alpha_is_the_adapters_anchor() -> None:
    sd, c = simdiff_net(), cond()
    x, t = torch.randn(3, 8, 263, generator=torch.Generator().manual_seed(4)), torch.tensor([700, 300, 50])
    with torch.no_grad():
        out = GuidedDenoiser(sd, 2.5, env_scale=3.0, anchor="reference", anchor_alpha=0.5)(x, t, c)
        adapters = GuidedDenoiser(sd, 2.5, env_scale=3.0)(x, t, c)
    assert torch.allclose(out, adapters, atol=1e-4)


def test_reference_anchor_costs_one_2b_and_one_4k_forward() -> None:
    sd, sizes = simdiff_net(), []

    def counting(x: torch.Tensor, t: torch.Tensor, c: Condition) -> torch.Tensor:
        sizes.append(x.shape[0])
        return sd(x, t, c)

    x, t = torch.randn(3, 8, 263), torch.tensor([300, 300, 300])
    with torch.no_grad():
        GuidedDenoiser(counting, 2.5, env_scale=4.0, anchor="reference", anchor_alpha=0.25)(x, t, cond())
        GuidedDenoiser(counting, 2.5, env_scale=4.0, anchor="reference")(x, t, earth(cond()))
    assert sizes == [6, 8, 6]  # two rows off φ_ref; then an all-Earth batch: the text guidance only
    with pytest.raises(SimdiffError, match="reference anchor needs a SimDiff model"):
        GuidedDenoiser(sd, 2.5, anchor="reference")(x, t, Condition(text=cond().text))


@pytest.mark.parametrize("anchor", ["reference", "backbone"])
def test_anchor_t_max_runs_the_adapters_anchor_at_the_early_steps(anchor: str) -> None:
    sd, c = simdiff_net(), cond()
    x = torch.randn(3, 8, 263, generator=torch.Generator().manual_seed(5))
    late = GuidedDenoiser(sd, 2.5, env_scale=4.0, anchor=anchor, anchor_alpha=0.25, anchor_t_max=500)
    every = GuidedDenoiser(sd, 2.5, env_scale=4.0, anchor=anchor, anchor_alpha=0.25)
    adapters = GuidedDenoiser(sd, 2.5, env_scale=4.0)
    with torch.no_grad():
        for step, expected in ((501, adapters), (900, adapters), (500, every), (20, every)):
            t = torch.full((3,), step)
            assert torch.equal(late(x, t, c), expected(x, t, c)), step
        assert not torch.allclose(every(x, torch.full((3,), 900), c), adapters(x, torch.full((3,), 900), c), atol=1e-4)
    with torch.no_grad():  # without environment guidance the early steps need no pass beyond the text guidance
        sizes = []
        GuidedDenoiser(lambda xx, tt, cc: sizes.append(xx.shape[0]) or sd(xx, tt, cc), 2.5, anchor=anchor,
                       anchor_t_max=500)(x, torch.full((3,), 900), c)
        assert sizes == [6]


def test_anchor_t_max_is_checked_in_one_line() -> None:
    for bad in (-1, 1000, 2.5, True):
        with pytest.raises(SimdiffError, match="anchor t max must be a whole timestep in 0..999"):
            GuidedDenoiser(simdiff_net(), 2.5, anchor="reference", anchor_t_max=bad)
    with pytest.raises(SimdiffError, match="anchor t max 500 needs the backbone or reference anchor"):
        GuidedDenoiser(simdiff_net(), 2.5, anchor_t_max=500)


def test_the_default_anchor_is_unchanged() -> None:
    sd, c = simdiff_net(), cond()
    x, t = torch.randn(3, 8, 263), torch.tensor([300, 300, 300])
    with torch.no_grad():
        assert torch.equal(GuidedDenoiser(sd, 2.5, env_scale=2.0)(x, t, c),
                           GuidedDenoiser(sd, 2.5, env_scale=2.0, anchor="adapters")(x, t, c))


def test_one_2k_forward_over_the_changed_rows_only() -> None:
    sd, c = simdiff_net(), cond()
    calls: list[tuple[int, object]] = []

    def counting(x, t, cc):
        calls.append((x.shape[0], cc.alpha if not isinstance(cc.alpha, torch.Tensor) else cc.alpha.tolist()))
        return sd(x, t, cc)

    x, t = torch.randn(3, 8, 263), torch.zeros(3, dtype=torch.long)
    with torch.no_grad():
        GuidedDenoiser(counting, 2.5, env_scale=1.0, anchor="backbone")(x, t, c)
        assert calls == [(6, 0.0), (4, 0.5)]  # the backbone's CFG pair, then φ and φ_ref of the two rows off Earth
        calls.clear()
        GuidedDenoiser(counting, 2.5, env_scale=2.0, anchor="backbone")(x, t, with_env(c, torch.tensor([REFERENCE_ENV] * 3)))
        assert calls == [(6, 0.0)]


def test_per_row_alpha_is_kept_in_the_push() -> None:
    sd = simdiff_net()
    c = cond(alpha=torch.tensor([0.2, 0.5, 1.0]))
    x, t = torch.randn(3, 8, 263), torch.tensor([300, 300, 300])
    with torch.no_grad():
        out = GuidedDenoiser(sd, 2.5, env_scale=2.0, anchor="backbone")(x, t, c)
        backbone = GuidedDenoiser(sd, 2.5)(x, t, with_env(c, ENVS, alpha=0.0))
        push = sd(x, t, c) - sd(x, t, with_env(c, torch.tensor([REFERENCE_ENV] * 3)))
    assert torch.allclose(out, backbone + 2.0 * push, atol=1e-4)


def test_bad_anchor_and_no_continuous_env_are_one_line_errors() -> None:
    with pytest.raises(SimdiffError, match="unknown guidance anchor 'sim'"):
        GuidedDenoiser(simdiff_net(), 2.5, anchor="sim")
    torch.manual_seed(0)
    backbone = MDMBackbone(backbone_preset("tiny")).eval()
    with pytest.raises(SimdiffError, match="backbone anchor needs a SimDiff model"):
        GuidedDenoiser(backbone, 2.5, anchor="backbone")(torch.randn(2, 8, 263), torch.zeros(2, dtype=torch.long),
                                                        Condition(text=torch.randn(2, 384)))


def test_sampling_earth_rows_equal_the_backbone_alone() -> None:
    sd, c = simdiff_net(), cond()
    s = make_scheduler("ddim", 6)
    anchored = sample(sd, s, c, 10, generator=torch.Generator().manual_seed(0), env_guidance=2.0, anchor="backbone")
    alone = sample(sd, s, with_env(c, ENVS, alpha=0.0), 10, generator=torch.Generator().manual_seed(0))
    assert torch.equal(anchored[1], alone[1])
    assert not torch.allclose(anchored[0], alone[0], atol=1e-3)


# --- the edit anchor ---------------------------------------------------------------------------------------

@pytest.mark.parametrize("env_scale", [1.0, 3.0])
def test_edit_anchor_follows_earth_above_edit_t_then_the_adapters_at_phi(env_scale: float) -> None:
    sd, c = simdiff_net(), cond()  # rows: g −1.6, Earth, wind
    x = torch.randn(3, 8, 263, generator=torch.Generator().manual_seed(6))
    edit = GuidedDenoiser(sd, 2.5, env_scale=env_scale, anchor="edit", anchor_alpha=0.25, edit_t=600)
    at_ref = GuidedDenoiser(sd, 2.5)  # the reference anchor's text guidance, used at φ_ref and α a
    adapters = GuidedDenoiser(sd, 2.5, env_scale=env_scale)
    reference = GuidedDenoiser(sd, 2.5, env_scale=env_scale, anchor="reference", anchor_alpha=0.25)
    with torch.no_grad():
        for step in (999, 601):
            t = torch.full((3,), step)
            out, base = edit(x, t, c), at_ref(x, t, earth(with_env(c, ENVS, alpha=0.25)))
            assert torch.allclose(out[:2], base[:2], atol=1e-5), step  # low g above edit t: at Earth
            assert torch.allclose(out[2], reference(x, t, c)[2], atol=1e-5), step  # wind alone: the reference anchor
            assert (out[2] - base[2]).abs().max() > 1e-3
        for step in (600, 20):
            t = torch.full((3,), step)
            out, base, phi = edit(x, t, c), at_ref(x, t, earth(with_env(c, ENVS, alpha=0.25))), adapters(x, t, c)
            assert torch.allclose(out[1], base[1], atol=1e-5), step  # the Earth row stays on the reference anchor
            assert torch.allclose(out[0], phi[0], atol=1e-5), step  # gravity off Earth's: the adapters anchor at φ
            assert torch.allclose(out[2], reference(x, t, c)[2], atol=1e-5), step
            assert (out[0] - base[0]).abs().max() > 1e-3


def test_edit_anchor_edits_a_row_with_both_gravity_and_wind() -> None:
    sd = simdiff_net()
    both = torch.tensor([[-1.6, 0.0, 10.0], [-9.81, 0.0, -10.0], [-9.81, 0.0, 0.0]])
    c = with_env(cond(), both)
    x, t = torch.randn(3, 8, 263, generator=torch.Generator().manual_seed(7)), torch.full((3,), 100)
    with torch.no_grad():
        out = GuidedDenoiser(sd, 2.5, anchor="edit", edit_t=500)(x, t, c)
        assert torch.allclose(out[0], GuidedDenoiser(sd, 2.5)(x, t, c)[0], atol=1e-5)
        assert torch.allclose(out[1:], GuidedDenoiser(sd, 2.5, anchor="reference")(x, t, c)[1:], atol=1e-5)


def test_edit_anchor_costs_one_2b_forward_per_step_and_the_wind_rows_reference_pass() -> None:
    sd, sizes = simdiff_net(), []

    def counting(x: torch.Tensor, t: torch.Tensor, c: Condition) -> torch.Tensor:
        sizes.append(x.shape[0])
        return sd(x, t, c)

    x = torch.randn(3, 8, 263)
    with torch.no_grad():
        GuidedDenoiser(counting, 2.5, anchor="edit", edit_t=500)(x, torch.full((3,), 900), cond())
        GuidedDenoiser(counting, 2.5, anchor="edit", edit_t=500)(x, torch.full((3,), 300), cond())
    # early: one batch at φ_ref and the wind row's φ / φ_ref pair; late: the same over the Earth and wind rows, then the
    # low-g row at its φ
    assert sizes == [6, 4, 4, 4, 2]


def test_edit_t_is_checked_in_one_line() -> None:
    from simdiff.diffusion.guidance import DEFAULT_EDIT_T
    from simdiff.product.request import DEFAULT_EDIT_T as REQUEST_DEFAULT

    assert GuidedDenoiser(simdiff_net(), 2.5, anchor="edit").edit_t == DEFAULT_EDIT_T == REQUEST_DEFAULT
    for bad in (-1, 1000, 2.5, True):
        with pytest.raises(SimdiffError, match="edit t must be a whole timestep in 0..999"):
            GuidedDenoiser(simdiff_net(), 2.5, anchor="edit", edit_t=bad)
    with pytest.raises(SimdiffError, match="edit t 500 needs the edit anchor"):
        GuidedDenoiser(simdiff_net(), 2.5, anchor="reference", edit_t=500)
    with pytest.raises(SimdiffError, match="anchor t max 500 needs the backbone or reference anchor"):
        GuidedDenoiser(simdiff_net(), 2.5, anchor="edit", anchor_t_max=500)


def test_sampling_with_the_edit_anchor_keeps_earth_rows_on_the_backbone() -> None:
    sd, c = simdiff_net(), cond()
    s = make_scheduler("ddim", 6)
    edited = sample(sd, s, c, 10, generator=torch.Generator().manual_seed(0), anchor="edit", edit_t=500)
    alone = sample(sd, s, with_env(c, ENVS, alpha=0.0), 10, generator=torch.Generator().manual_seed(0))
    assert torch.allclose(edited[1], alone[1], atol=1e-5)
    assert not torch.allclose(edited[0], alone[0], atol=1e-3)


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
