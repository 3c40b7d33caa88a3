"""Weights I/O (model.safetensors + config.json) and the inference-only MotionGenerator."""

from __future__ import annotations

import json

import pytest
import torch

from simdiff.diffusion.config import SamplingConfig
from simdiff.errors import SimdiffError
from simdiff.model import ModelConfig, SimConfig, backbone_preset, build_network, load_pretrained
from simdiff.inference.generator import MotionGenerator


class HashText:
    name = "minilm"
    dim = 384

    def encode(self, texts: list[str]) -> torch.Tensor:
        return torch.stack([torch.randn(384, generator=torch.Generator().manual_seed(len(t) * 7919 + ord(t[0]))) for t in texts])


def tiny(sim: bool = False) -> ModelConfig:
    return ModelConfig(backbone=backbone_preset("tiny"), sim=SimConfig() if sim else None)


def test_save_load_round_trip(tmp_path) -> None:
    config = tiny(sim=True)
    gen = MotionGenerator(build_network(config), config, HashText(), torch.full((263,), 2.0), torch.full((263,), 3.0))
    gen.save(tmp_path)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["config.json", "model.safetensors"]
    assert json.loads((tmp_path / "config.json").read_text())["sim"]["mode"] == "continuous"
    net, cfg, extra = load_pretrained(tmp_path)
    assert cfg == config
    for key, value in gen.network.state_dict().items():
        assert torch.equal(net.state_dict()[key], value)
    assert torch.equal(extra["normalizer.std"], torch.full((263,), 3.0))


def cfg(**kw) -> SamplingConfig:
    return SamplingConfig(**{"steps": 3, **kw})


def test_generate_shapes_lengths_and_seed(tmp_path) -> None:
    config = tiny()
    gen = MotionGenerator(build_network(config), config, HashText(), torch.full((263,), 1.0), torch.full((263,), 2.0))
    out = gen.generate(["a person walks", "a person jumps"], [30, 20], cfg(steps=5), seed=3)
    assert out.features.shape == (2, 30, 263)
    assert torch.all(out.features[1, 20:] == 0)
    assert torch.allclose(out.features[0], out.normalized[0] * 2 + 1)
    again = gen.generate(["a person walks", "a person jumps"], [30, 20], cfg(steps=5), seed=3)
    assert torch.equal(out.features, again.features)
    assert [c.shape[0] for c in out.clips()] == [30, 20]


def test_generate_rejects_bad_input() -> None:
    gen = MotionGenerator(build_network(tiny()), tiny(), HashText())
    with pytest.raises(SimdiffError, match="196"):
        gen.generate(["walk"], 197, cfg(steps=2))
    with pytest.raises(SimdiffError, match="backbone-only"):
        gen.generate(["walk"], 20, cfg(steps=2), env=(-9.81, 0, 0))
    sim = MotionGenerator(build_network(tiny(True)), tiny(True), HashText())
    with pytest.raises(SimdiffError, match="env must be"):
        sim.generate(["walk"] * 2, 20, cfg(steps=2), env=[1.0, 2.0])
    assert sim.generate(["walk"] * 2, 20, cfg(steps=2, alpha=0.5), env=(-3.0, 5.0, 0.0)).features.shape == (2, 20, 263)


def test_earth_rows_are_the_backbone_alone() -> None:
    gen = reacting_generator()
    envs = [[-9.81, 0.0, 0.0], [-1.6, 0.0, 0.0]]
    out = gen.generate(["walk", "jump"], 12, cfg(alpha=0.5, env_guidance=2.0, edit_t=500), env=envs, seed=1).features
    backbone = MotionGenerator(gen.network.backbone, tiny(), HashText())
    alone = backbone.generate(["walk", "jump"], 12, cfg(), seed=1).features
    assert torch.allclose(out[0], alone[0], atol=1e-5) and not torch.allclose(out[1], alone[1], atol=1e-4)


def test_edit_t_sets_where_gravity_enters() -> None:
    gen = reacting_generator()
    envs = [[-9.81, 0.0, 0.0], [-1.6, 0.0, 0.0]]
    kw = dict(env=envs, seed=1)
    never = gen.generate(["walk", "jump"], 12, cfg(alpha=0.5, edit_t=0, steps=4), **kw).features
    late = gen.generate(["walk", "jump"], 12, cfg(alpha=0.5, edit_t=500, steps=4), **kw).features
    every = gen.generate(["walk", "jump"], 12, cfg(alpha=0.5, edit_t=999, steps=4), **kw).features
    assert torch.allclose(never[0], every[0], atol=1e-5)  # Earth is the backbone whatever edit_t
    assert not torch.allclose(never[1], late[1], atol=1e-4) and not torch.allclose(late[1], every[1], atol=1e-4)


def test_load_pretrained_missing_folder(tmp_path) -> None:
    with pytest.raises(SimdiffError, match="config.json"):
        load_pretrained(tmp_path / "nope")


def reacting_generator() -> MotionGenerator:
    """A tiny continuous SimDiff generator whose adapters answer φ (jittered up-projections)."""
    config = tiny(True)
    torch.manual_seed(0)
    net = build_network(config)
    for a in net.adapters:
        torch.nn.init.normal_(a.up.weight, std=0.3)
    return MotionGenerator(net, config, HashText())


def test_env_guidance_changes_only_motions_off_earth_and_is_validated() -> None:
    gen = reacting_generator()
    envs = [[-9.81, 0.0, 0.0], [-1.6, 0.0, 0.0]]
    plain = gen.generate(["walk", "jump"], 12, cfg(alpha=0.5, edit_t=999), env=envs, seed=1).features
    pushed = gen.generate(["walk", "jump"], 12, cfg(alpha=0.5, edit_t=999, env_guidance=3.0), env=envs, seed=1).features
    assert torch.equal(plain[0], pushed[0]) and not torch.allclose(plain[1], pushed[1], atol=1e-4)
    backbone = MotionGenerator(build_network(tiny()), tiny(), HashText())
    with pytest.raises(SimdiffError, match="continuous Sim Encoder"):
        backbone.generate(["walk"], 12, cfg(steps=2, env_guidance=2.0))


@pytest.mark.parametrize("mask_frames", [True, False])
def test_masked_batch_gives_each_sample_at_its_own_length(mask_frames: bool) -> None:
    """With ``mask_frames`` a short sample in a padded batch is the sample its length gives alone (same noise);
    without it (MDM) the padded frames are denoised as motion too and the short sample is a crop of a longer one."""
    from simdiff.diffusion.sampling import sample
    from simdiff.model.condition import Condition

    config = ModelConfig(backbone=backbone_preset("tiny", mask_frames=mask_frames), sim=SimConfig())
    torch.manual_seed(0)
    net = build_network(config).eval()
    for a in net.adapters:
        torch.nn.init.normal_(a.up.weight, std=0.3)
    text = HashText().encode(["a person walks", "a person jumps"])
    lengths = torch.tensor([20, 12])
    env = torch.tensor([[-1.6, 0.0, 0.0], [-1.6, 3.0, 0.0]])
    x_init = torch.randn(2, 20, 263, generator=torch.Generator().manual_seed(5))
    kw = dict(config=SamplingConfig(steps=5, env_guidance=2.0, edit_t=999))
    batch = sample(net, cond=Condition(text=text, frame_mask=torch.arange(20)[None] < lengths[:, None],
                                                            env=env, alpha=0.5), num_frames=20, x_init=x_init, **kw)
    alone = sample(net, cond=Condition(text=text[1:], frame_mask=torch.ones(1, 12, dtype=torch.bool),
                                                            env=env[1:], alpha=0.5), num_frames=12, x_init=x_init[1:, :12], **kw)
    assert torch.allclose(batch[1, :12], alone[0], atol=1e-4) is mask_frames
    first = sample(net, cond=Condition(text=text[:1], frame_mask=torch.ones(1, 20, dtype=torch.bool),
                                                            env=env[:1], alpha=0.5), num_frames=20, x_init=x_init[:1], **kw)
    assert torch.allclose(batch[0], first[0], atol=1e-4)  # the longest sample has no padding either way


def test_single_prompt_embeddings_are_cached_and_batches_encoded_whole(monkeypatch) -> None:
    import simdiff.inference.generator as generator_module

    class Counting(HashText):
        def __init__(self) -> None:
            self.seen: list[list[str]] = []

        def encode(self, texts: list[str]) -> torch.Tensor:
            self.seen.append(list(texts))
            return super().encode(texts)

    encoder = Counting()
    config = tiny()
    gen = MotionGenerator(build_network(config), config, encoder)
    first = gen.encode_text(["a person walks"])
    first.add_(1.0)  # a caller changing its copy does not change the cache
    assert torch.equal(gen.encode_text(["a person walks"]), HashText().encode(["a person walks"]))
    gen.encode_text(["a person walks", "a person jumps"])
    gen.encode_text(["a person walks", "a person jumps"])
    assert encoder.seen == [["a person walks"]] + [["a person walks", "a person jumps"]] * 2
    monkeypatch.setattr(generator_module, "EMBEDDING_CACHE", 2)
    for text in ["b", "c", "a person walks"]:
        gen.encode_text([text])
    assert encoder.seen[-3:] == [["b"], ["c"], ["a person walks"]]  # the oldest went first
    gen.text_encoder = HashText()  # another encoder: nothing cached from the first one is reused
    assert torch.equal(gen.encode_text(["b"]), HashText().encode(["b"])) and encoder.seen[-1] == ["a person walks"]
    monkeypatch.setattr(generator_module, "EMBEDDING_CACHE", 0)  # 0 turns the cache off
    gen.encode_text(["z"])
    assert "z" not in gen._embedded
