"""Convert OpenAI's TorchScript ``ViT-B-32.pt`` to a safetensors file of its text tower, once.

``torch.jit.load`` runs code stored in the archive, so :mod:`simdiff.text.clip` refuses such
files; this tool is the one place that loads one, on a file the user names and trusts::

    python -m simdiff.text.clip_convert ViT-B-32.pt ViT-B-32.safetensors
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

import torch

from simdiff.errors import SimdiffError

TEXT_KEYS: tuple[str, ...] = ("token_embedding.", "positional_embedding", "transformer.", "ln_final.", "text_projection")
"""OpenAI key prefixes of the text tower (everything else, ``visual.*`` and ``logit_scale``, is dropped)."""


def convert(src: str | os.PathLike[str], dst: str | os.PathLike[str]) -> int:
    """Load the trusted TorchScript archive ``src``, write its text-tower tensors to ``dst``; returns their count."""
    from simdiff.fsio import atomic_save_tensors

    src, dst = Path(src), Path(dst)
    if not src.is_file():
        raise SimdiffError(f"{src}: file not found")
    try:
        state = torch.jit.load(str(src), map_location="cpu").state_dict()
    except RuntimeError as exc:
        raise SimdiffError(f"{src}: not a TorchScript archive ({str(exc).splitlines()[0]})") from None
    text = {k: v.detach().float().contiguous() for k, v in state.items() if k.startswith(TEXT_KEYS)}
    if "token_embedding.weight" not in text:
        raise SimdiffError(f"{src}: no CLIP text tower (token_embedding.weight missing)")
    atomic_save_tensors(text, dst)
    return len(text)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m simdiff.text.clip_convert", description=__doc__.splitlines()[0])
    parser.add_argument("src", help="OpenAI's ViT-B-32.pt (a file you trust)")
    parser.add_argument("dst", help="output .safetensors")
    args = parser.parse_args(argv)
    try:
        n = convert(args.src, args.dst)
    except SimdiffError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    print(f"{args.dst}: {n} text-tower tensors")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
