"""What every stage reads: the run folder, the config, injected pieces (text encoder, projector)."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

import torch

from simdiff.train.pipeline.config import PipelineConfig


@dataclass
class PipelineContext:
    """Shared state of one pipeline run.

    Attributes:
        out: the run folder (one sub-folder per stage, ``stages/`` markers).
        config: the settings.
        device: where the training and evaluation stages run.
        text_encoder: injected encoder (tests); default: ``config.text_encoder`` loaded once.
        projector: injected simulator projector for the augmentation stage (tests).
        progress: show progress bars.
        log: one-line progress messages.
    """

    out: Path
    config: PipelineConfig
    device: torch.device = torch.device("cpu")
    text_encoder: Any = None
    projector: Any = None
    progress: bool = True
    log: Callable[[str], None] = print
    keys: dict[str, str] = field(default_factory=dict)

    def text(self) -> Any:
        """The text encoder: injected, else ``config.text_table``'s captions when set, else the named encoder."""
        if self.text_encoder is None:
            if self.config.text_table:
                from simdiff.text.table import open_caption_table

                self.text_encoder = open_caption_table(self.config.text_table, self.config.text_encoder, self.device)
            else:
                from simdiff.text.base import load_text_encoder

                self.text_encoder = load_text_encoder(self.config.text_encoder, self.device)
        return self.text_encoder

    def text_settings(self) -> dict[str, Any]:
        """What of the text side enters a stage's key: the encoder, and the table's content when one is used."""
        out: dict[str, Any] = {"text_encoder": self.config.text_encoder}
        if self.config.text_table:
            import hashlib

            from simdiff.errors import SimdiffError

            try:
                out["text_table_sha256"] = hashlib.sha256(Path(self.config.text_table).read_bytes()).hexdigest()
            except OSError:
                raise SimdiffError(f"text table not found: {self.config.text_table}") from None
        return out

    def corpus_dir(self) -> Path:
        c = self.config.corpus
        if c.path and not _is_pack(Path(c.path)):
            return Path(c.path)
        return self.out / "corpus"

    def augmented_dir(self) -> Path:
        a = self.config.augment
        if a.path and not _is_pack(Path(a.path)):
            return Path(a.path)
        return self.out / "augmented"

    def section(self, name: str) -> dict[str, Any]:
        return dataclasses.asdict(getattr(self.config, name))


def _is_pack(path: Path) -> bool:
    from simdiff.data.pack import is_pack

    return is_pack(path)
