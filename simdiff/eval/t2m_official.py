"""Loader for the official T2M evaluator (Guo et al. 2022) for users who have its files.

Files (from the text-to-motion release; not shipped, not downloaded):

* ``text_mot_match/model/finest.tar``: a dict with state dicts ``movement_encoder``,
  ``text_encoder``, ``motion_encoder`` (and ``epoch``). Read with ``torch.load(...,
  weights_only=True)``: tensors and plain containers only, never arbitrary objects.
* ``glove/our_vab_data.npy`` (V, 300) and ``our_vab_words.pkl`` / ``our_vab_idx.pkl`` (a
  word list and a word→row dict). The pickles are read with an unpickler that refuses every
  global, so only lists/dicts/strings/ints load.
* ``meta/mean.npy``, ``meta/std.npy``: the evaluator's feature statistics (t2m_mean/std).

Networks (facts file §3.1; parameter names follow the checkpoint's):

* ``MovementConvEncoder(259, 512, 512)``: Conv1d(259→512, k4 s2 p1) · Dropout · LeakyReLU ·
  Conv1d(512→512, k4 s2 p1) · Dropout · LeakyReLU, then Linear(512→512) (``main.0``,
  ``main.3``, ``out_net``);
* ``MotionEncoderBiGRUCo(512, 1024, 512)``: ``input_emb`` 512→1024, BiGRU 1024, learned
  ``hidden`` (2, 1, 1024), ``output_net`` Linear(2048→1024) · LayerNorm · LeakyReLU · Linear(1024→512);
* ``TextEncoderBiGRUCo(300, 15, 512, 512)``: ``pos_emb`` 15→300 added to the word vector,
  ``input_emb`` 300→512, BiGRU 512, ``hidden`` (2, 1, 512), ``output_net`` 1024→512 · LN ·
  LeakyReLU · 512→512.

Text input: tokens ``word/POS`` → ``sos/OTHER`` + first 20 + ``eos/OTHER``, padded with
``unk/OTHER`` to 22; POS one-hot over 15 classes, VIP word lists overriding the tag; unknown
words → ``unk`` with OTHER. Motion input: ``(x − t2m_mean)/t2m_std`` without the contacts,
GRU over ``length // 4`` tokens.
"""

from __future__ import annotations

import io
import pickle
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
import torch
from torch import Tensor, nn

from simdiff.errors import SimdiffError
from simdiff.eval.encoders import BiGRUEncoder, MovementConvEncoder

POS_TAGS: tuple[str, ...] = ("VERB", "NOUN", "DET", "ADP", "NUM", "AUX", "PRON", "ADJ", "ADV", "Loc_VIP", "Body_VIP",
                             "Obj_VIP", "Act_VIP", "Desc_VIP", "OTHER")
VIP_WORDS: dict[str, frozenset[str]] = {
    "Loc_VIP": frozenset("left right clockwise counterclockwise anticlockwise forward back backward up down straight curve".split()),
    "Body_VIP": frozenset("arm chin foot feet face hand mouth leg waist eye knee shoulder thigh".split()),
    "Obj_VIP": frozenset("stair dumbbell chair window floor car ball handrail baseball basketball".split()),
    "Act_VIP": frozenset(("walk run swing pick bring kick put squat throw hop dance jump turn stumble stop sit lift lower "
                          "raise wash stand kneel stroll rub bend balance flap jog shuffle lean rotate spin spread climb").split()),
    "Desc_VIP": frozenset("slowly carefully fast careful slow quickly happy angry sad happily angrily sadly".split()),
}
MAX_TEXT_TOKENS: int = 20
UNIT_LENGTH: int = 4

EXPECTED_SHAPES: dict[str, dict[str, tuple[int, ...]]] = {
    "movement_encoder": {
        "main.0.weight": (512, 259, 4), "main.0.bias": (512,), "main.3.weight": (512, 512, 4), "main.3.bias": (512,),
        "out_net.weight": (512, 512), "out_net.bias": (512,),
    },
    "motion_encoder": {
        "input_emb.weight": (1024, 512), "input_emb.bias": (1024,), "hidden": (2, 1, 1024),
        **{f"gru.{w}_{k}_l0{s}": shape for s in ("", "_reverse")
           for w, k, shape in (("weight", "ih", (3072, 1024)), ("weight", "hh", (3072, 1024)),
                               ("bias", "ih", (3072,)), ("bias", "hh", (3072,)))},
        "output_net.0.weight": (1024, 2048), "output_net.0.bias": (1024,), "output_net.1.weight": (1024,),
        "output_net.1.bias": (1024,), "output_net.3.weight": (512, 1024), "output_net.3.bias": (512,),
    },
    "text_encoder": {
        "pos_emb.weight": (300, 15), "pos_emb.bias": (300,), "input_emb.weight": (512, 300), "input_emb.bias": (512,),
        "hidden": (2, 1, 512),
        **{f"gru.{w}_{k}_l0{s}": shape for s in ("", "_reverse")
           for w, k, shape in (("weight", "ih", (1536, 512)), ("weight", "hh", (1536, 512)),
                               ("bias", "ih", (1536,)), ("bias", "hh", (1536,)))},
        "output_net.0.weight": (512, 1024), "output_net.0.bias": (512,), "output_net.1.weight": (512,),
        "output_net.1.bias": (512,), "output_net.3.weight": (512, 512), "output_net.3.bias": (512,),
    },
}
"""Parameter shapes of the released ``finest.tar`` (facts §3.1)."""


class MotionEncoderBiGRUCo(BiGRUEncoder):
    """(B, N, 512) movement tokens, (B,) token counts → (B, 512)."""

    def __init__(self, in_dim: int = 512, hidden: int = 1024, out_dim: int = 512) -> None:
        super().__init__(in_dim, hidden, out_dim)

    def forward(self, tokens: Tensor, counts: Tensor) -> Tensor:
        return self.encode(tokens, counts)


class TextEncoderBiGRUCo(BiGRUEncoder):
    """(B, L, 300) word vectors, (B, L, 15) POS one-hots, (B,) lengths → (B, 512)."""

    def __init__(self, word_dim: int = 300, pos_dim: int = 15, hidden: int = 512, out_dim: int = 512) -> None:
        super().__init__(word_dim, hidden, out_dim)
        self.pos_emb = nn.Linear(pos_dim, word_dim)

    def forward(self, words: Tensor, pos: Tensor, lengths: Tensor) -> Tensor:
        return self.encode(words + self.pos_emb(pos), lengths)


class _NoGlobals(pickle.Unpickler):
    def find_class(self, module: str, name: str) -> Any:  # noqa: D401 - pickle hook
        raise pickle.UnpicklingError(f"refusing to load {module}.{name} (only plain lists/dicts are allowed)")


def _safe_pickle(path: Path) -> Any:
    if not path.is_file():
        raise SimdiffError(f"{path}: missing GloVe file")
    try:
        return _NoGlobals(io.BytesIO(path.read_bytes())).load()
    except (pickle.UnpicklingError, EOFError, ValueError) as exc:
        raise SimdiffError(f"{path}: not a plain pickle of words ({exc})") from None


class WordVectorizer:
    """GloVe vectors + POS one-hots for ``word/POS`` tokens (T2M's vocabulary files)."""

    def __init__(self, vectors: np.ndarray, word_to_row: dict[str, int]) -> None:
        if "unk" not in word_to_row:
            raise SimdiffError("GloVe vocabulary has no 'unk' entry")
        self.vectors = np.asarray(vectors, dtype=np.float32)
        self.word_to_row = word_to_row

    @classmethod
    def from_dir(cls, folder: str | Path, prefix: str = "our_vab") -> "WordVectorizer":
        folder = Path(folder)
        data = folder / f"{prefix}_data.npy"
        if not data.is_file():
            raise SimdiffError(f"{data}: missing GloVe file")
        vectors = np.load(data, allow_pickle=False)
        words = _safe_pickle(folder / f"{prefix}_words.pkl")
        index = _safe_pickle(folder / f"{prefix}_idx.pkl")
        if not isinstance(index, dict) or not isinstance(words, (list, tuple)):
            raise SimdiffError(f"{folder}: unexpected GloVe vocabulary format")
        return cls(vectors, {w: int(index[w]) for w in words})

    @staticmethod
    def pos_onehot(tag: str) -> np.ndarray:
        vec = np.zeros(len(POS_TAGS), dtype=np.float32)
        vec[POS_TAGS.index(tag) if tag in POS_TAGS else POS_TAGS.index("OTHER")] = 1.0
        return vec

    def __getitem__(self, token: str) -> tuple[np.ndarray, np.ndarray]:
        word, _, tag = token.partition("/")
        if word not in self.word_to_row:
            return self.vectors[self.word_to_row["unk"]], self.pos_onehot("OTHER")
        vip = next((k for k, words in VIP_WORDS.items() if word in words), None)
        return self.vectors[self.word_to_row[word]], self.pos_onehot(vip or tag)

    def encode(self, tokens: Sequence[str]) -> tuple[np.ndarray, np.ndarray, int]:
        """``word/POS`` tokens → (22, 300) words, (22, 15) POS, sentence length incl. sos/eos."""
        seq = ["sos/OTHER", *list(tokens)[:MAX_TEXT_TOKENS], "eos/OTHER"]
        length = len(seq)
        seq += ["unk/OTHER"] * (MAX_TEXT_TOKENS + 2 - length)
        words, pos = zip(*(self[t] for t in seq))
        return np.stack(words), np.stack(pos), length


def load_finest(path: str | Path, device: torch.device | str = "cpu") -> dict[str, nn.Module]:
    """The three official networks from ``finest.tar`` (eval mode), after checking every shape."""
    path = Path(path)
    if not path.is_file():
        raise SimdiffError(f"{path}: T2M evaluator checkpoint not found")
    try:
        ckpt = torch.load(path, map_location="cpu", weights_only=True)
    except Exception as exc:  # noqa: BLE001 - anything unreadable is a user-file problem
        raise SimdiffError(f"{path}: cannot read as a weights-only checkpoint ({type(exc).__name__})") from None
    return build_from_state(ckpt, str(path), device)


def build_from_state(ckpt: dict[str, Any], where: str = "checkpoint", device: torch.device | str = "cpu") -> dict[str, nn.Module]:
    """Build and load the networks from a ``finest.tar``-style dict, checking names and shapes."""
    if not isinstance(ckpt, dict):
        raise SimdiffError(f"{where}: expected a dict of state dicts")
    nets = {"movement_encoder": MovementConvEncoder(), "motion_encoder": MotionEncoderBiGRUCo(),
            "text_encoder": TextEncoderBiGRUCo()}
    for name, net in nets.items():
        if name not in ckpt:
            raise SimdiffError(f"{where}: no {name!r} entry")
        state = {k.removeprefix("module."): v for k, v in ckpt[name].items()}
        expected = EXPECTED_SHAPES[name]
        missing = sorted(set(expected) - set(state))
        extra = sorted(set(state) - set(expected))
        if missing or extra:
            key = (missing or extra)[0]
            raise SimdiffError(f"{where}: {name} {'lacks' if missing else 'has unexpected'} parameter {key!r}")
        for key, shape in expected.items():
            if tuple(state[key].shape) != shape:
                raise SimdiffError(f"{where}: {name}.{key} has shape {tuple(state[key].shape)}, expected {shape}")
        net.load_state_dict({k: v.float() for k, v in state.items()}, strict=True)
        net.to(device).eval().requires_grad_(False)
    return nets


class OfficialT2MEvaluator:
    """The official evaluator behind the protocol's interface (``embed_motion``, ``embed_text``).

    Args:
        nets: from :func:`load_finest`.
        words: a :class:`WordVectorizer`.
        mean, std: (263,) t2m evaluator statistics (``meta/mean.npy``, ``meta/std.npy``).
    """

    name = "t2m"

    def __init__(self, nets: dict[str, nn.Module], words: WordVectorizer, mean: np.ndarray, std: np.ndarray,
                 device: torch.device | str = "cpu") -> None:
        self.nets = nets
        self.words = words
        self.device = torch.device(device)
        self.mean = torch.as_tensor(np.asarray(mean, dtype=np.float32), device=self.device)
        self.std = torch.as_tensor(np.asarray(std, dtype=np.float32), device=self.device)

    @classmethod
    def from_files(cls, checkpoint: str | Path, glove_dir: str | Path, meta_dir: str | Path,
                   device: torch.device | str = "cpu") -> "OfficialT2MEvaluator":
        from simdiff.motion.normalize import Normalizer

        norm = Normalizer.from_files(Path(meta_dir) / "mean.npy", Path(meta_dir) / "std.npy")
        return cls(load_finest(checkpoint, device), WordVectorizer.from_dir(glove_dir), norm.mean, norm.std, device)

    @torch.no_grad()
    def embed_motion(self, features: Tensor, lengths: Tensor | Sequence[int]) -> np.ndarray:
        """(B, T, 263) raw features, (B,) frames → (B, 512)."""
        lengths = torch.as_tensor(lengths, dtype=torch.long)
        x = ((features.float().to(self.device) - self.mean) / self.std)[..., :-4]
        mask = torch.arange(x.shape[1], device=x.device)[None] < lengths.to(x.device)[:, None]
        tokens = self.nets["movement_encoder"](x * mask[..., None])
        return self.nets["motion_encoder"](tokens, lengths // UNIT_LENGTH).double().cpu().numpy()

    @torch.no_grad()
    def embed_text(self, captions: Sequence[str], tokens: Sequence[Sequence[str]] | None = None) -> np.ndarray:
        """``word/POS`` token lists (the caption files' second field) → (B, 512)."""
        if tokens is None:
            raise SimdiffError("the official T2M evaluator needs word/POS tokens for each caption")
        enc = [self.words.encode(t) for t in tokens]
        words = torch.from_numpy(np.stack([e[0] for e in enc])).to(self.device)
        pos = torch.from_numpy(np.stack([e[1] for e in enc])).to(self.device)
        lens = torch.tensor([e[2] for e in enc])
        return self.nets["text_encoder"](words, pos, lens).double().cpu().numpy()
