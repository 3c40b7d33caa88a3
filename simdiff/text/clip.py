"""CLIP ViT-B/32 text tower from a local weights file (MDM's text condition, 512-d).

CLIP weights cannot be downloaded at run time; the user supplies them:

* ``weights``: a ``.safetensors`` or plain ``.pt`` state dict with OpenAI's key names (``token_embedding.weight``,
  ``positional_embedding``, ``transformer.resblocks.i.*``, ``ln_final.*``, ``text_projection``;
  ``visual.*`` keys are ignored). Plain ``.pt`` files are read with ``weights_only=True``.
  OpenAI's own ``ViT-B-32.pt`` is a TorchScript archive, and loading one runs code stored in
  the file, so it is refused; convert a copy you trust once with
  ``python -m simdiff.text.clip_convert ViT-B-32.pt ViT-B-32.safetensors``.
* the BPE vocabulary ``bpe_simple_vocab_16e6.txt.gz`` beside the weights file (or at
  ``$SIMDIFF_CLIP_BPE``).

Captions are tokenised as MDM does for HumanML3D: at most 20 BPE tokens between SOT and EOT.
"""

from __future__ import annotations

import gzip
import html
import os
import re
from functools import lru_cache
from pathlib import Path
from typing import Sequence

import torch
from torch import Tensor, nn

from simdiff.errors import SimdiffError

BPE_NAME = "bpe_simple_vocab_16e6.txt.gz"
MAX_TEXT_TOKENS = 20
"""MDM truncates HumanML3D captions to 20 tokens (context 22 with SOT/EOT, then padded to 77)."""


@lru_cache(maxsize=1)
def _byte_to_unicode() -> dict[int, str]:
    """GPT-2's reversible byte → printable-unicode table."""
    keep = list(range(ord("!"), ord("~") + 1)) + list(range(ord("¡"), ord("¬") + 1)) + list(range(ord("®"), ord("ÿ") + 1))
    table = {b: chr(b) for b in keep}
    extra = 0
    for b in range(256):
        if b not in table:
            table[b] = chr(256 + extra)
            extra += 1
    return table


_PATTERN = re.compile(r"<\|startoftext\|>|<\|endoftext\|>|'s|'t|'re|'ve|'m|'ll|'d|[^\W\d_]+|\d|[^\s\w]+|_+", re.IGNORECASE)


class CLIPTokenizer:
    """Byte-level BPE tokenizer read from CLIP's merges file."""

    def __init__(self, merges: list[tuple[str, str]]) -> None:
        units = list(_byte_to_unicode().values())
        vocab = units + [u + "</w>" for u in units] + ["".join(m) for m in merges] + ["<|startoftext|>", "<|endoftext|>"]
        self.encoder = {tok: i for i, tok in enumerate(vocab)}
        self.ranks = {m: i for i, m in enumerate(merges)}
        self.sot = self.encoder["<|startoftext|>"]
        self.eot = self.encoder["<|endoftext|>"]
        self._cache: dict[str, list[str]] = {}

    @classmethod
    def from_file(cls, path: str | Path) -> "CLIPTokenizer":
        """Read ``bpe_simple_vocab_16e6.txt.gz`` (first line a header; 48,894 merges used)."""
        lines = gzip.open(path, "rt", encoding="utf-8").read().split("\n")
        merges = [tuple(line.split()) for line in lines[1 : 49152 - 256 - 2 + 1] if line.strip()]
        return cls([m for m in merges if len(m) == 2])  # type: ignore[misc]

    def _bpe(self, token: str) -> list[str]:
        if token in self._cache:
            return self._cache[token]
        word = list(token[:-1]) + [token[-1] + "</w>"]
        while len(word) > 1:
            pairs = [(self.ranks.get((a, b), 1 << 30), i) for i, (a, b) in enumerate(zip(word, word[1:]))]
            rank, _ = min(pairs)
            if rank == 1 << 30:
                break
            first, second = next((word[i], word[i + 1]) for r, i in pairs if r == rank)
            merged, i = [], 0
            while i < len(word):
                if i < len(word) - 1 and word[i] == first and word[i + 1] == second:
                    merged.append(first + second)
                    i += 2
                else:
                    merged.append(word[i])
                    i += 1
            word = merged
        self._cache[token] = word
        return word

    def encode(self, text: str, max_tokens: int = MAX_TEXT_TOKENS) -> list[int]:
        """``[SOT] ids… [EOT]`` with at most ``max_tokens`` ids between them."""
        text = re.sub(r"\s+", " ", html.unescape(html.unescape(text))).strip().lower()
        table = _byte_to_unicode()
        ids: list[int] = []
        for piece in _PATTERN.findall(text):
            unit = "".join(table[b] for b in piece.encode("utf-8"))
            ids.extend(self.encoder[t] for t in self._bpe(unit) if t in self.encoder)
        return [self.sot] + ids[:max_tokens] + [self.eot]


class _ResidualBlock(nn.Module):
    """Pre-LN block with QuickGELU, named like OpenAI CLIP's ``ResidualAttentionBlock``."""

    def __init__(self, dim: int, heads: int) -> None:
        super().__init__()
        self.attn = nn.MultiheadAttention(dim, heads, batch_first=True)
        self.ln_1 = nn.LayerNorm(dim)
        self.mlp = nn.Sequential()
        self.mlp.add_module("c_fc", nn.Linear(dim, 4 * dim))
        self.mlp.add_module("c_proj", nn.Linear(4 * dim, dim))
        self.ln_2 = nn.LayerNorm(dim)

    def forward(self, x: Tensor, causal: Tensor) -> Tensor:
        h = self.ln_1(x)
        x = x + self.attn(h, h, h, attn_mask=causal, need_weights=False)[0]
        h = self.mlp.c_fc(self.ln_2(x))
        return x + self.mlp.c_proj(h * torch.sigmoid(1.702 * h))


class _Transformer(nn.Module):
    def __init__(self, dim: int, layers: int, heads: int) -> None:
        super().__init__()
        self.resblocks = nn.ModuleList(_ResidualBlock(dim, heads) for _ in range(layers))


class CLIPTextEncoder(nn.Module):
    """CLIP text features (B, 512), float32, not normalised (MDM feeds ``encode_text`` directly)."""

    name = "clip"

    def __init__(self, vocab_size: int, context: int, width: int, layers: int, heads: int, embed_dim: int,
                 tokenizer: CLIPTokenizer) -> None:
        super().__init__()
        self.token_embedding = nn.Embedding(vocab_size, width)
        self.positional_embedding = nn.Parameter(torch.zeros(context, width))
        self.transformer = _Transformer(width, layers, heads)
        self.ln_final = nn.LayerNorm(width)
        self.text_projection = nn.Parameter(torch.zeros(width, embed_dim))
        self.tokenizer = tokenizer
        self.dim = embed_dim
        self.requires_grad_(False)
        self.eval()

    @classmethod
    def from_state_dict(cls, state: dict[str, Tensor], tokenizer: CLIPTokenizer) -> "CLIPTextEncoder":
        """Build from OpenAI-named weights; sizes are read from the shapes (heads = width / 64)."""
        try:
            vocab, width = state["token_embedding.weight"].shape
            context = state["positional_embedding"].shape[0]
            embed_dim = state["text_projection"].shape[1]
        except KeyError as exc:
            raise SimdiffError(f"CLIP weights lack {exc.args[0]}") from None
        layers = len({k.split(".")[2] for k in state if k.startswith("transformer.resblocks.")})
        model = cls(int(vocab), int(context), int(width), layers, max(1, int(width) // 64), int(embed_dim), tokenizer)
        own = model.state_dict()
        model.load_state_dict({k: v.float() for k, v in state.items() if k in own}, strict=True)
        return model

    @classmethod
    def from_file(cls, weights: str | os.PathLike[str] | None, device: torch.device | str = "cpu") -> "CLIPTextEncoder":
        """Load ``weights`` (see the module docstring) and the BPE file; clear errors name what is missing."""
        if weights is None:
            raise SimdiffError("the clip text encoder needs a local ViT-B-32 weights file (pass --clip-weights PATH)")
        path = Path(weights)
        if not path.is_file():
            raise SimdiffError(f"{path}: CLIP ViT-B/32 weights file not found")
        bpe = Path(os.environ.get("SIMDIFF_CLIP_BPE", path.parent / BPE_NAME))
        if not bpe.is_file():
            raise SimdiffError(f"{bpe}: CLIP BPE vocabulary not found (put {BPE_NAME} beside the weights)")
        state = _read_state(path)
        return cls.from_state_dict(state, CLIPTokenizer.from_file(bpe)).to(device)

    @torch.no_grad()
    def encode(self, texts: Sequence[str]) -> Tensor:
        """(B,) captions → (B, 512) float32: the EOT token's final state times ``text_projection``."""
        device = self.token_embedding.weight.device
        context = self.positional_embedding.shape[0]
        ids = torch.zeros((len(texts), context), dtype=torch.long)
        eot = torch.zeros(len(texts), dtype=torch.long)
        for i, text in enumerate(texts):
            tokens = self.tokenizer.encode(text, max_tokens=min(MAX_TEXT_TOKENS, context - 2))
            ids[i, : len(tokens)] = torch.tensor(tokens)
            eot[i] = len(tokens) - 1
        ids, eot = ids.to(device), eot.to(device)
        causal = torch.full((context, context), float("-inf"), device=device).triu(1)
        x = self.token_embedding(ids) + self.positional_embedding
        for block in self.transformer.resblocks:
            x = block(x, causal)
        x = self.ln_final(x)
        return x[torch.arange(len(texts), device=device), eot] @ self.text_projection


def is_torchscript(path: str | os.PathLike[str]) -> bool:
    """True for a TorchScript archive (a zip holding ``code/`` or ``constants.pkl``), which only
    ``torch.jit.load`` reads, running the code it carries."""
    import zipfile

    if not zipfile.is_zipfile(path):
        return False
    with zipfile.ZipFile(path) as archive:
        return any("/code/" in n or n.endswith("/constants.pkl") for n in archive.namelist())


def _read_state(path: Path) -> dict[str, Tensor]:
    """Weights from a safetensors file or a plain state-dict ``.pt`` (never a TorchScript archive)."""
    if path.suffix == ".safetensors":
        from safetensors.torch import load_file

        try:
            return load_file(str(path))
        except Exception as exc:  # noqa: BLE001 - safetensors raises several kinds
            raise SimdiffError(f"{path}: not a readable safetensors file ({exc})") from None
    if is_torchscript(path):
        raise SimdiffError(f"{path} is a TorchScript archive, whose loading runs code from the file; convert a copy you "
                           f"trust once: python -m simdiff.text.clip_convert {path} {path.with_suffix('.safetensors')}")
    try:
        raw = torch.load(str(path), map_location="cpu", weights_only=True)
    except Exception as exc:  # noqa: BLE001 - pickle / zip errors of a damaged or foreign file
        raise SimdiffError(f"{path}: not a CLIP state dict of plain tensors ({type(exc).__name__})") from None
    raw = raw.get("state_dict", raw) if isinstance(raw, dict) else raw
    if not isinstance(raw, dict):
        raise SimdiffError(f"{path}: holds a {type(raw).__name__}, not a state dict")
    return dict(raw)
