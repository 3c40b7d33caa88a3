"""SimDiff: Sim Encoder, zero-initialised Motion Adapters, exact equalities with the backbone."""

from __future__ import annotations

import pytest
import torch

from simdiff.errors import SimdiffError
from simdiff.model import Condition, MDMBackbone, MotionAdapter, SimConfig, SimDiffNet, SimEncoder, backbone_preset
from simdiff.model.simdiff_net import adapter_bottleneck


def make(mode: str = "continuous") -> tuple[SimDiffNet, MDMBackbone]:
    torch.manual_seed(0)
    cfg = backbone_preset("tiny", dropout=0.1)
    backbone = MDMBackbone(cfg)
    net = SimDiffNet(cfg, SimConfig(mode=mode, num_categories=5))
    net.backbone.load_state_dict(backbone.state_dict())
    return net.eval(), backbone.eval()


def inputs(b: int = 3, t: int = 20) -> tuple[torch.Tensor, torch.Tensor, Condition]:
    g = torch.Generator().manual_seed(4)
    x = torch.randn(b, t, 263, generator=g)
    ts = torch.randint(0, 1000, (b,), generator=g)
    env = torch.tensor([[-9.81, 0.0, 0.0], [-3.0, 10.0, 0.0], [-20.0, -5.0, 5.0]])[:b]
    return x, ts, Condition(text=torch.randn(b, 384, generator=g), env=env, env_index=torch.arange(b))


@pytest.mark.parametrize("mode", ["continuous", "categorical"])
def test_initial_simdiff_equals_backbone_exactly(mode: str) -> None:
    net, backbone = make(mode)
    x, t, c = inputs()
    with torch.no_grad():
        assert torch.equal(net(x, t, c), backbone(x, t, Condition(text=c.text)))
        # Also under CFG halves (text dropped) and with a mask.
        cu = c.unconditional()
        assert torch.equal(net(x, t, cu), backbone(x, t, Condition(text=c.text, uncond=cu.uncond)))


def test_alpha_zero_equals_backbone_after_adapters_are_trained() -> None:
    net, backbone = make()
    for adapter in net.adapters:
        torch.nn.init.normal_(adapter.up.weight, std=0.5)
        torch.nn.init.normal_(adapter.up.bias, std=0.5)
    x, t, c = inputs()
    with torch.no_grad():
        ref = backbone(x, t, Condition(text=c.text))
        assert not torch.allclose(net(x, t, c), ref)
        c.alpha = 0.0
        assert torch.equal(net(x, t, c), ref)
        c.alpha = torch.zeros(3)
        assert torch.equal(net(x, t, c), ref)
        c.alpha = torch.tensor([0.0, 1.0, 0.0])
        out = net(x, t, c)
        assert torch.equal(out[0], ref[0]) and torch.equal(out[2], ref[2]) and not torch.allclose(out[1], ref[1])


def test_alpha_zero_skips_the_adapters() -> None:
    net, _ = make()
    calls: list[int] = []
    for adapter in net.adapters:
        adapter.register_forward_hook(lambda *_: calls.append(1))
    x, t, c = inputs()
    with torch.no_grad():
        c.alpha = torch.zeros(3)
        net(x, t, c)
        assert not calls
        c.alpha = torch.tensor([0.0, 1.0, 0.0])
        net(x, t, c)
    assert len(calls) == len(net.adapters)


def test_adapter_formula_and_zero_init() -> None:
    a = MotionAdapter(8, 4)
    assert torch.count_nonzero(a.up.weight) == 0 and torch.count_nonzero(a.up.bias) == 0
    torch.nn.init.normal_(a.up.weight)
    h, e = torch.randn(2, 5, 8), torch.randn(2, 8)
    expected = h + 0.5 * a.up(torch.nn.functional.silu(a.down(h + a.sim(e)[:, None])))
    assert torch.allclose(a(h, e, 0.5), expected)


def test_sim_encoder_modes_and_scaling() -> None:
    enc = SimEncoder(SimConfig(), 32)
    scaled = enc.scale(torch.tensor([[-9.81, 10.0, -10.0], [-19.62, 0.0, 0.0]]))
    assert torch.allclose(scaled, torch.tensor([[0.0, 1.0, -1.0], [-1.0, 0.0, 0.0]]))
    assert enc(torch.zeros(4, 3)).shape == (4, 32)
    with pytest.raises(SimdiffError, match="env"):
        enc(None, torch.zeros(4, dtype=torch.long))
    cat = SimEncoder(SimConfig(mode="categorical", num_categories=3), 32)
    assert cat(env_index=torch.tensor([0, 2])).shape == (2, 32)
    with pytest.raises(SimdiffError, match="env_index"):
        cat(env_index=torch.tensor([3]))


def test_two_adapters_per_layer_and_bottleneck() -> None:
    net, _ = make()
    assert len(net.adapters) == 2 * net.backbone.config.num_layers
    assert adapter_bottleneck(SimConfig(), 512) == 256
    assert adapter_bottleneck(SimConfig(), 64) == 32
    assert adapter_bottleneck(SimConfig(bottleneck=16), 512) == 16


def test_only_sim_parameters_get_gradients() -> None:
    net, _ = make()
    net.train()
    net.backbone.requires_grad_(False)
    for adapter in net.adapters:  # non-zero W_up so every adapter parameter gets a gradient
        torch.nn.init.normal_(adapter.up.weight, std=0.1)
    x, t, c = inputs()
    net(x, t, c).square().mean().backward()
    assert all(p.grad is None for p in net.backbone.parameters())
    trained = {id(p) for p in net.adapter_parameters()}
    assert all(p.grad is not None and p.grad.abs().sum() > 0 for p in net.adapter_parameters())
    assert all(id(p) in trained for p in net.parameters() if p.grad is not None)


def test_guidance_pair_keeps_env_and_drops_text_only_in_second_half() -> None:
    _, _, c = inputs()
    pair = c.with_guidance_pair()
    assert pair.uncond.tolist() == [False] * 3 + [True] * 3
    assert torch.equal(pair.env[:3], c.env) and torch.equal(pair.env[3:], c.env)
    assert torch.equal(pair.env_index[3:], c.env_index)
