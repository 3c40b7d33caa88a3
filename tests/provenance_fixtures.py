"""Synthetic corpus manifests for the provenance tests (made up here; no real data)."""

from __future__ import annotations

import json
from pathlib import Path


def clip(cid: str, licence: str, seconds: float, split: str = "train", source: str = "cmu-amc",
         mirror_of: str | None = None) -> dict:
    """One manifest clip record with the fields provenance reads."""
    return {"id": cid, "licence": licence, "seconds": seconds, "split": split, "source": source, "mirror_of": mirror_of}


def write_manifest(folder: Path, clips: list[dict], licence: str = "all", fmt: str = "simdiff-corpus") -> Path:
    """Write ``folder/manifest.json`` in the corpus builder's layout (only the keys provenance reads)."""
    folder.mkdir(parents=True, exist_ok=True)
    sources = sorted({c.get("source", "") for c in clips})
    (folder / "manifest.json").write_text(json.dumps({"format": fmt, "licence": licence, "sources": sources,
                                                      "clips": clips}), encoding="utf-8")
    return folder


def write_augmented(folder: Path, sources: list[str], corpus: Path | None = None) -> Path:
    """An augmented folder's ``env.json`` (one kept pair per source clip) and, with ``corpus``, its source record."""
    folder.mkdir(parents=True, exist_ok=True)
    env = {f"{s}_e{k:02d}": {"env": [-9.81, 0.0, 0.0], "env_index": 1, "condition": k, "factor": "earth", "source": s}
           for k, s in enumerate(sources)}
    (folder / "env.json").write_text(json.dumps(env), encoding="utf-8")
    if corpus is not None:
        from simdiff.model.provenance import SOURCE_CORPUS_NAME, source_record

        (folder / SOURCE_CORPUS_NAME).write_text(json.dumps(source_record(corpus, set(sources))), encoding="utf-8")
    return folder
