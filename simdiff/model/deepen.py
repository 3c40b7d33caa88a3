"""Deepen a trained backbone without changing what it computes: insert identity transformer layers.

A post-LN layer computes ``h1 = LN1(h + attn(h))``, ``out = LN2(h1 + ff(h1))``. A new layer with its attention
output projection and its second feed-forward linear at zero computes ``LN2'(LN1'(h))``; LayerNorm of a tensor that
is already normalised (mean 0, variance 1 per token) is that tensor (to ε/σ² ≈ 1e-5), so the layer is the identity on
the *un-scaled* output of the layer before it. The insertion therefore moves the preceding layer's ``norm2``
affine (γ, β) onto the new layer's ``norm2`` and sets the old one to (1, 0): the deeper network gives the same x̂₀
(float32 rounding aside) and training can then use the new layers (Net2Net-style growth, Chen et al. 2016).

Motion Adapters (two per layer, after ``norm1`` and after ``norm2``) keep their inputs: the adapter after the old
layer's ``norm2`` moves to after the new layer's ``norm2``; the two adapter slots the new layer opens are fresh
zero-initialised adapters (the identity exactly). The Sim Encoder, normaliser, ``sampling.json`` and provenance are
the source model's; ``deepening.json`` records the recipe.
"""

from __future__ import annotations

import contextlib
import dataclasses
import os
from collections.abc import Iterator, Sequence
from pathlib import Path

import torch
from torch import Tensor

from simdiff.errors import SimdiffError
from simdiff.fsio import write_json
from simdiff.model.adapter import MotionAdapter
from simdiff.model.backbone import EncoderLayer
from simdiff.model.checkpoint import build_network, load_pretrained, save_derived
from simdiff.model.config import BackboneConfig
from simdiff.model.shards import weights_sha256
from simdiff.model.simdiff_net import SimDiffNet, adapter_bottleneck

RECIPE_NAME = "deepening.json"
COPIED = ("sampling.json", "provenance.json")
_LAYER = "seqTransEncoder.layers."


@contextlib.contextmanager
def _seeded_from(generator: torch.Generator) -> Iterator[None]:
    """Module initialisation inside draws from a seed taken from ``generator``; the global RNG is left as it was."""
    with torch.random.fork_rng(devices=[]):
        torch.manual_seed(int(torch.randint(0, 2**31 - 1, (1,), generator=generator)))
        yield


def _identity_layer(old: dict[str, Tensor], config: BackboneConfig, generator: torch.Generator) -> dict[str, Tensor]:
    """A fresh layer's weights (PyTorch's default init under ``generator``) with zero output paths; ``norm2`` = old's."""
    c = config
    with _seeded_from(generator):
        layer = EncoderLayer(c.latent_dim, c.num_heads, c.ff_size, c.dropout, c.activation)
    state = {k: v.detach().clone() for k, v in layer.state_dict().items()}
    for key in ("self_attn.out_proj.weight", "self_attn.out_proj.bias", "linear2.weight", "linear2.bias"):
        state[key].zero_()
    state["norm1.weight"].fill_(1.0)
    state["norm1.bias"].zero_()
    state["norm2.weight"] = old["norm2.weight"].clone()
    state["norm2.bias"] = old["norm2.bias"].clone()
    return state


def deepen_state(state: dict[str, Tensor], prefix: str, config: BackboneConfig, after: Sequence[int],
                 generator: torch.Generator,
                 fresh_adapter: dict[str, Tensor] | None = None) -> dict[str, Tensor]:
    """The state dict of the deepened network (backbone keys under ``prefix``; adapters under ``adapters.``).

    ``after``: indices of the old layers each followed by one new layer. ``fresh_adapter``: a zero-initialised
    adapter's weights (None for a backbone-only model).
    """
    n = config.num_layers
    layers = [{k[len(f"{prefix}{_LAYER}{i}."):]: v for k, v in state.items() if k.startswith(f"{prefix}{_LAYER}{i}.")}
              for i in range(n)]
    adapters = ([{k[len(f"adapters.{j}."):]: v for k, v in state.items() if k.startswith(f"adapters.{j}.")}
                 for j in range(2 * n)] if fresh_adapter is not None else None)
    out = {k: v for k, v in state.items() if not k.startswith(f"{prefix}{_LAYER}") and not k.startswith("adapters.")}
    new_layers: list[dict[str, Tensor]] = []
    new_adapters: list[dict[str, Tensor]] = []
    for i in range(n):
        old = dict(layers[i])
        if i in after:
            inserted = _identity_layer(old, config, generator)
            old["norm2.weight"] = torch.ones_like(old["norm2.weight"])
            old["norm2.bias"] = torch.zeros_like(old["norm2.bias"])
            new_layers += [old, inserted]
            if adapters is not None:
                new_adapters += [adapters[2 * i], fresh_adapter, fresh_adapter, adapters[2 * i + 1]]
        else:
            new_layers.append(old)
            if adapters is not None:
                new_adapters += [adapters[2 * i], adapters[2 * i + 1]]
    for i, layer in enumerate(new_layers):
        out.update({f"{prefix}{_LAYER}{i}.{k}": v.clone() for k, v in layer.items()})
    for j, adapter in enumerate(new_adapters):
        out.update({f"adapters.{j}.{k}": v.clone() for k, v in adapter.items()})
    return out


def deepen_model(model: str | os.PathLike[str], out: str | os.PathLike[str], after: Sequence[int] | None = None,
                 seed: int = 0) -> Path:
    """Write ``out``: ``model`` with one identity layer inserted after each layer in ``after`` (default: every one).

    The new layers' attention in-projections and first feed-forward linears get PyTorch's default initialisation
    under ``seed``. Refused (one line) when ``after`` names a layer the model lacks or ``out`` is ``model``.
    """
    src, dst = Path(model), Path(out)
    if dst.resolve() == src.resolve():
        raise SimdiffError(f"{dst}: the output folder must differ from the model")
    network, config, extra = load_pretrained(src)
    bb = config.backbone
    after = sorted(set(range(bb.num_layers) if after is None else after))
    bad = [i for i in after if not 0 <= i < bb.num_layers]
    if bad or not after:
        raise SimdiffError(f"--after {bad[0] if bad else '(empty)'}: the model has layers 0..{bb.num_layers - 1}")
    simdiff = isinstance(network, SimDiffNet)
    new_config = dataclasses.replace(config, backbone=dataclasses.replace(bb, num_layers=bb.num_layers + len(after)))
    new_net = build_network(new_config)
    generator = torch.Generator().manual_seed(int(seed))
    fresh = None
    if simdiff:  # one zero adapter (its input side drawn under the seed) fills every new slot
        with _seeded_from(generator):
            adapter = MotionAdapter(bb.latent_dim, adapter_bottleneck(config.sim, bb.latent_dim))
        fresh = {k: v.detach().clone() for k, v in adapter.state_dict().items()}
    state = deepen_state(network.state_dict(), "backbone." if simdiff else "", bb, after, generator, fresh)
    new_net.load_state_dict(state)
    save_derived(dst, new_net, new_config, extra, src, COPIED)
    write_json(dst / RECIPE_NAME, {
        "rule": "one identity layer (zero attention out-projection and second feed-forward linear) after each "
                "listed layer; the preceding layer's norm2 affine moved onto it; fresh adapters zero",
        "after": after, "seed": int(seed), "layers": [bb.num_layers, new_config.backbone.num_layers],
        "model": str(src), "model_sha256": weights_sha256(src)})
    return dst
