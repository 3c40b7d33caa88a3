"""Sampling loop: CFG (batched = unbatched, formula), x₀ hook, masked loss."""

from __future__ import annotations

import torch

from simdiff.diffusion.config import SamplingConfig
from simdiff.diffusion.guidance import GuidedDenoiser
from simdiff.diffusion.losses import diffusion_loss, masked_mse
from simdiff.diffusion.sampling import make_scheduler, sample
from simdiff.diffusion.losses import lengths_to_mask
from simdiff.model import Condition, MDMBackbone, SimConfig, SimDiffNet, backbone_preset


def net() -> MDMBackbone:
    torch.manual_seed(0)
    return MDMBackbone(backbone_preset("tiny")).eval()


def cond(b: int = 2) -> Condition:
    return Condition(text=torch.randn(b, 384, generator=torch.Generator().manual_seed(2)))


def test_cfg_formula_and_batched_equals_unbatched() -> None:
    model, c = net(), cond()
    x, t = torch.randn(2, 16, 263), torch.tensor([100, 900])
    with torch.no_grad():
        xc, xu = model(x, t, c), model(x, t, c.unconditional())
        batched = GuidedDenoiser(model, 2.5, batched=True)(x, t, c)
        unbatched = GuidedDenoiser(model, 2.5, batched=False)(x, t, c)
        assert torch.allclose(unbatched, xu + 2.5 * (xc - xu), atol=1e-6)
        assert torch.allclose(batched, unbatched, atol=1e-5)
        assert torch.equal(GuidedDenoiser(model, 1.0)(x, t, c), xc)


def test_batched_cfg_is_one_forward() -> None:
    model, c = net(), cond(3)
    calls = []

    def counting(x, t, cc):
        calls.append(x.shape[0])
        return model(x, t, cc)

    with torch.no_grad():
        GuidedDenoiser(counting, 2.5, batched=True)(torch.randn(3, 8, 263), torch.zeros(3, dtype=torch.long), c)
    assert calls == [6]


def test_cfg_keeps_adapters_active_in_both_halves() -> None:
    torch.manual_seed(0)
    sd = SimDiffNet(backbone_preset("tiny"), SimConfig()).eval()
    for a in sd.adapters:
        torch.nn.init.normal_(a.up.weight, std=0.3)
    c = cond()
    c.env = torch.tensor([[-3.0, 10.0, 0.0], [-9.81, 0.0, 0.0]])
    x, t = torch.randn(2, 8, 263), torch.tensor([50, 50])
    with torch.no_grad():
        u_with_env = sd(x, t, c.unconditional())
        out = GuidedDenoiser(sd, 2.5)(x, t, c)
        # the row off Earth's gravity, at a step below edit_t: CFG with the adapters on in both passes
        assert torch.allclose(out[0], (u_with_env + 2.5 * (sd(x, t, c) - u_with_env))[0], atol=1e-5)


def test_sampling_is_seeded_and_hook_replaces_x0_at_chosen_steps() -> None:
    model, c = net(), cond()
    seen = []
    target = torch.full((2, 12, 263), 0.25)

    def hook(x0, t, xt):
        seen.append(t)
        return target

    s = SamplingConfig()
    a = sample(model, s, c, 12, generator=torch.Generator().manual_seed(0))
    b = sample(model, s, c, 12, generator=torch.Generator().manual_seed(0))
    assert torch.equal(a, b) and a.shape == (2, 12, 263)
    out = sample(model, s, c, 12, generator=torch.Generator().manual_seed(0), x0_hook=hook, hook_timesteps=[60, 40, 20, 0])
    assert seen == [60, 40, 20, 0]
    assert torch.allclose(out, target, atol=1e-6)  # projected x̂ at t = 0 is the output
    ddpm = make_scheduler("ddpm", 20)
    seen.clear()
    sample(model, SamplingConfig(sampler="ddpm", steps=20, guidance=1.0), c, 12, generator=torch.Generator().manual_seed(0), x0_hook=hook)
    assert seen == ddpm.timesteps.tolist()


def test_masked_mse_ignores_padding() -> None:
    pred, target = torch.zeros(2, 4, 263), torch.zeros(2, 4, 263)
    pred[0, :2] = 1.0
    pred[1, 3] = 100.0  # padded frame of sample 1
    mask = lengths_to_mask(torch.tensor([4, 3]), 4)
    assert masked_mse(pred, target, mask).item() == (0.5 + 0.0) / 2


def test_diffusion_loss_is_seeded() -> None:
    model, c = net(), cond()
    x0, mask = torch.randn(2, 10, 263), lengths_to_mask(torch.tensor([10, 6]), 10)
    s = make_scheduler("ddpm")
    with torch.no_grad():
        a = diffusion_loss(model, s, x0, c, mask, torch.Generator().manual_seed(5))
        b = diffusion_loss(model, s, x0, c, mask, torch.Generator().manual_seed(5))
    assert torch.equal(a, b) and a.item() > 0
