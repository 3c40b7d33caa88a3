"""MDM backbone: shapes, sizes, the official-checkpoint key layout, attention masking."""

from __future__ import annotations

import pytest
import torch

from simdiff.errors import SimdiffError
from simdiff.model import Condition, MDMBackbone, backbone_preset, load_mdm_checkpoint, load_mdm_state_dict
from simdiff.model.backbone import sinusoidal_table
from simdiff.model.checkpoint import mdm_backbone_config


pytestmark = pytest.mark.usefixtures("one_torch_thread")


D = 512


def official_mdm_state_dict(layers: int = 8, seed: int = 0) -> dict[str, torch.Tensor]:
    """A state dict with exactly the official MDM names and shapes (facts §2.3), random values."""
    g = torch.Generator().manual_seed(seed)
    r = lambda *shape: torch.randn(*shape, generator=g) * 0.02  # noqa: E731
    sd = {
        "sequence_pos_encoder.pe": torch.zeros(5000, 1, D),
        "embed_timestep.sequence_pos_encoder.pe": torch.zeros(5000, 1, D),
        "input_process.poseEmbedding.weight": r(D, 263), "input_process.poseEmbedding.bias": r(D),
        "embed_timestep.time_embed.0.weight": r(D, D), "embed_timestep.time_embed.0.bias": r(D),
        "embed_timestep.time_embed.2.weight": r(D, D), "embed_timestep.time_embed.2.bias": r(D),
        "embed_text.weight": r(D, 512), "embed_text.bias": r(D),
        "output_process.poseFinal.weight": r(263, D), "output_process.poseFinal.bias": r(263),
        "clip_model.token_embedding.weight": r(10, 4),
        "clip_model.positional_embedding": r(77, 4),
    }
    for i in range(layers):
        p = f"seqTransEncoder.layers.{i}."
        sd.update({
            p + "self_attn.in_proj_weight": r(3 * D, D), p + "self_attn.in_proj_bias": r(3 * D),
            p + "self_attn.out_proj.weight": r(D, D), p + "self_attn.out_proj.bias": r(D),
            p + "linear1.weight": r(1024, D), p + "linear1.bias": r(1024),
            p + "linear2.weight": r(D, 1024), p + "linear2.bias": r(D),
            p + "norm1.weight": 1 + r(D), p + "norm1.bias": r(D),
            p + "norm2.weight": 1 + r(D), p + "norm2.bias": r(D),
        })
    return sd


def cond(b: int, text_dim: int, seed: int = 1) -> Condition:
    return Condition(text=torch.randn(b, text_dim, generator=torch.Generator().manual_seed(seed)))


def test_mdm_preset_matches_paper_size() -> None:
    net = MDMBackbone(backbone_preset("mdm", text_dim=512))
    n = sum(p.numel() for p in net.parameters())
    assert n == 17_880_327  # facts §2.1: about 17.9M excluding CLIP
    layer = net.seqTransEncoder.layers[0]
    assert layer.linear1.out_features == 1024 and layer.self_attn.num_heads == 4


def test_official_keys_and_shapes_match_exactly() -> None:
    sd = official_mdm_state_dict()
    ours = MDMBackbone(backbone_preset("mdm", text_dim=512)).state_dict()
    theirs = {k: v for k, v in sd.items() if not k.startswith("clip_model.") and not k.endswith(".pe")}
    assert set(ours) == set(theirs)
    assert all(ours[k].shape == theirs[k].shape for k in ours)


def test_official_loader_round_trips(tmp_path) -> None:
    sd = official_mdm_state_dict()
    path = tmp_path / "model000475000.pt"
    torch.save(sd, path)
    net = load_mdm_checkpoint(path)
    assert net.config.latent_dim == 512 and net.config.num_layers == 8 and net.config.text_dim == 512
    loaded = net.state_dict()
    for key, value in loaded.items():
        assert torch.equal(value, sd[key]), key
    # EMA checkpoints: {'model', 'model_avg'} → the average is used.
    avg = official_mdm_state_dict(seed=3)
    torch.save({"model": sd, "model_avg": avg}, tmp_path / "ema.pt")
    net2 = load_mdm_checkpoint(tmp_path / "ema.pt")
    assert torch.equal(net2.embed_text.weight, avg["embed_text.weight"])
    # And it runs: (B, T, 263) → (B, T, 263).
    out = net.eval()(torch.randn(2, 30, 263), torch.tensor([0, 999]), cond(2, 512))
    assert out.shape == (2, 30, 263)


def test_official_loader_rejects_wrong_shapes_and_missing_file(tmp_path) -> None:
    sd = official_mdm_state_dict(layers=2)
    sd["embed_text.weight"] = torch.zeros(512, 384)
    net = MDMBackbone(backbone_preset("mdm", num_layers=2, text_dim=512))
    with pytest.raises(SimdiffError, match="embed_text.weight"):
        load_mdm_state_dict(net, sd)
    with pytest.raises(SimdiffError, match="no such MDM checkpoint"):
        load_mdm_checkpoint(tmp_path / "missing.pt")
    assert mdm_backbone_config(official_mdm_state_dict(layers=3)).num_layers == 3


def test_pe_table_matches_formula() -> None:
    pe = sinusoidal_table(10, 8)
    pos, i = 7, 2
    div = torch.exp(torch.tensor(2.0 * i) * (-torch.log(torch.tensor(10000.0)) / 8))
    assert torch.allclose(pe[pos, 2 * i], torch.sin(pos * div)) and torch.allclose(pe[pos, 2 * i + 1], torch.cos(pos * div))


def test_output_shape_and_determinism_in_eval() -> None:
    net = MDMBackbone(backbone_preset("tiny")).eval()
    x, t, c = torch.randn(3, 17, 263), torch.tensor([1, 500, 999]), cond(3, 384)
    a, b = net(x, t, c), net(x, t, c)
    assert a.shape == (3, 17, 263) and torch.equal(a, b)


def test_uncond_zeroes_the_text() -> None:
    net = MDMBackbone(backbone_preset("tiny")).eval()
    x, t = torch.randn(2, 9, 263), torch.tensor([10, 10])
    c = cond(2, 384)
    dropped = Condition(text=c.text, uncond=torch.tensor([True, True]))
    zero = Condition(text=torch.zeros_like(c.text))
    assert torch.equal(net(x, t, dropped), net(x, t, zero))
    assert not torch.allclose(net(x, t, c), net(x, t, zero))


def test_attention_mask_optional() -> None:
    torch.manual_seed(0)
    plain = MDMBackbone(backbone_preset("tiny"))
    masked = MDMBackbone(backbone_preset("tiny", mask_frames=True))
    masked.load_state_dict(plain.state_dict())
    plain.eval(), masked.eval()
    x, t = torch.randn(2, 12, 263), torch.tensor([5, 700])
    mask = torch.tensor([[True] * 12, [True] * 7 + [False] * 5])
    c = Condition(text=torch.randn(2, 384), frame_mask=mask)
    # Off reproduces MDM: the mask is ignored, padded frames influence valid ones.
    x2 = x.clone()
    x2[1, 7:] = 5.0
    assert torch.equal(plain(x, t, c), plain(x, t, Condition(text=c.text)))
    assert not torch.allclose(plain(x, t, c)[1, :7], plain(x2, t, c)[1, :7])
    # On: valid frames ignore padded content.
    assert torch.allclose(masked(x, t, c)[1, :7], masked(x2, t, c)[1, :7], atol=1e-5)
    full = Condition(text=c.text, frame_mask=torch.ones(2, 12, dtype=torch.bool))
    assert torch.equal(masked(x, t, full), plain(x, t, full))  # no padding: the unmasked path, bit for bit


def test_forward_matches_torch_transformer_encoder_reference() -> None:
    """Our written-out layers equal MDM's construction: seq-first nn.TransformerEncoder (post-LN, GELU)."""
    cfg = backbone_preset("tiny", dropout=0.1)
    torch.manual_seed(0)
    net = MDMBackbone(cfg).eval()
    layer = torch.nn.TransformerEncoderLayer(cfg.latent_dim, cfg.num_heads, cfg.ff_size, 0.1, activation="gelu")
    reference = torch.nn.TransformerEncoder(layer, cfg.num_layers, enable_nested_tensor=False).eval()
    reference.load_state_dict({k[len("seqTransEncoder."):]: v for k, v in net.state_dict().items()
                               if k.startswith("seqTransEncoder.")})
    x, t = torch.randn(2, 15, 263), torch.tensor([3, 640])
    text = torch.randn(2, 384)
    with torch.no_grad():
        pe = sinusoidal_table(cfg.max_len, cfg.latent_dim)[:, None, :]  # [5000, 1, d] as MDM registers it
        emb = net.embed_timestep.time_embed(pe[t].permute(1, 0, 2)) + net.embed_text(text)[None]  # [1, B, d]
        seq = torch.cat([emb, net.input_process.poseEmbedding(x.permute(1, 0, 2))]) + pe[:16]  # [T+1, B, d]
        expected = net.output_process.poseFinal(reference(seq)[1:]).permute(1, 0, 2)
        assert torch.allclose(net(x, t, Condition(text=text)), expected, atol=1e-5)
