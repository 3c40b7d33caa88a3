"""Official T2M evaluator loader: documented parameter shapes, weights-only loading, GloVe pickles."""

from __future__ import annotations

import pickle
from pathlib import Path

import numpy as np
import pytest
import torch

from simdiff.errors import SimdiffError
from simdiff.eval.t2m_official import (EXPECTED_SHAPES, MotionEncoderBiGRUCo, MovementConvEncoder, OfficialT2MEvaluator,
                                       TextEncoderBiGRUCo, WordVectorizer, load_finest)


def synthetic_state() -> dict:
    g = torch.Generator().manual_seed(0)
    return {name: {k: torch.randn(shape, generator=g) * 0.05 for k, shape in shapes.items()}
            for name, shapes in EXPECTED_SHAPES.items()} | {"epoch": 7}


def test_our_modules_have_exactly_the_documented_shapes() -> None:
    for name, net in (("movement_encoder", MovementConvEncoder()), ("motion_encoder", MotionEncoderBiGRUCo()),
                      ("text_encoder", TextEncoderBiGRUCo())):
        assert {k: tuple(v.shape) for k, v in net.state_dict().items()} == EXPECTED_SHAPES[name]


def test_load_synthetic_finest_and_embed(tmp_path: Path) -> None:
    path = tmp_path / "finest.tar"
    torch.save(synthetic_state(), path)
    nets = load_finest(path)
    words = WordVectorizer(np.random.default_rng(0).normal(size=(4, 300)).astype(np.float32),
                           {"unk": 0, "walk": 1, "person": 2, "a": 3})
    ev = OfficialT2MEvaluator(nets, words, np.zeros(263), np.ones(263))
    m = ev.embed_motion(torch.randn(2, 40, 263), [40, 24])
    t = ev.embed_text(["a person walks"] * 2, [["a/DET", "person/NOUN", "walk/VERB"], ["zzz/NOUN"]])
    assert m.shape == (2, 512) and t.shape == (2, 512)
    with pytest.raises(SimdiffError, match="tokens"):
        ev.embed_text(["a person walks"])


def test_wrong_shapes_and_keys_are_named(tmp_path: Path) -> None:
    state = synthetic_state()
    state["motion_encoder"]["input_emb.weight"] = torch.zeros(1024, 263)
    torch.save(state, tmp_path / "bad.tar")
    with pytest.raises(SimdiffError, match=r"motion_encoder.input_emb.weight has shape \(1024, 263\)"):
        load_finest(tmp_path / "bad.tar")
    state = synthetic_state()
    del state["text_encoder"]["pos_emb.bias"]
    torch.save(state, tmp_path / "missing.tar")
    with pytest.raises(SimdiffError, match="lacks parameter 'pos_emb.bias'"):
        load_finest(tmp_path / "missing.tar")
    with pytest.raises(SimdiffError, match="not found"):
        load_finest(tmp_path / "none.tar")


class Evil:
    def __reduce__(self):
        return (print, ("pwned",))


def test_untrusted_objects_are_refused(tmp_path: Path) -> None:
    torch.save({"movement_encoder": Evil()}, tmp_path / "evil.tar")
    with pytest.raises(SimdiffError, match="weights-only"):
        load_finest(tmp_path / "evil.tar")
    np.save(tmp_path / "our_vab_data.npy", np.zeros((2, 300), np.float32))
    (tmp_path / "our_vab_words.pkl").write_bytes(pickle.dumps(Evil()))
    (tmp_path / "our_vab_idx.pkl").write_bytes(pickle.dumps({"unk": 0}))
    with pytest.raises(SimdiffError, match="plain pickle"):
        WordVectorizer.from_dir(tmp_path)
    (tmp_path / "our_vab_words.pkl").write_bytes(pickle.dumps(["unk", "walk"]))
    (tmp_path / "our_vab_idx.pkl").write_bytes(pickle.dumps({"unk": 0, "walk": 1}))
    assert len(WordVectorizer.from_dir(tmp_path).word_to_row) == 2


def test_tokens_pos_and_vip_words() -> None:
    vecs = np.arange(4 * 300, dtype=np.float32).reshape(4, 300)
    words = WordVectorizer(vecs, {"unk": 0, "walk": 1, "left": 2, "sos": 3, "eos": 3})
    w, pos, n = words.encode(["walk/NOUN", "left/ADJ", "blorp/VERB"])
    assert n == 5 and w.shape == (22, 300) and pos.shape == (22, 15)
    assert pos[1].argmax() == 12  # Act_VIP overrides NOUN
    assert pos[2].argmax() == 9  # Loc_VIP
    assert pos[3].argmax() == 14 and np.array_equal(w[3], vecs[0])  # unknown → unk / OTHER
    assert words.encode(["walk/VERB"] * 30)[2] == 22
