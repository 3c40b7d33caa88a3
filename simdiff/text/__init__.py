"""Text encoders behind one interface: MiniLM (default, shipped weights) and CLIP (local file)."""

from simdiff.text.base import TEXT_DIMS, TextEncoder, load_text_encoder, text_dim
from simdiff.text.cache import CachedTextEncoder

__all__ = ["TEXT_DIMS", "TextEncoder", "CachedTextEncoder", "load_text_encoder", "text_dim"]
