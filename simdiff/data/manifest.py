"""The corpus ``manifest.json`` of ``simdiff data build``, read and checked in one place.

Every command that reads a corpus manifest (``data report``, ``data loop``, ``data augment``'s classes) goes
through :func:`read_manifest`: a missing, unreadable, non-JSON or wrongly shaped manifest, or a clip record
lacking a field the caller needs, is one :class:`~simdiff.errors.SimdiffError` line naming the file and the
problem.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from simdiff.errors import SimdiffError

MANIFEST_NAME: str = "manifest.json"
"""File name of a corpus manifest."""

CLIP_KEYS: tuple[str, ...] = ("id",)
"""Fields every clip record must have."""
LOOP_CLIP_KEYS: tuple[str, ...] = ("id", "motion_type", "frames")
"""Fields ``simdiff data loop`` reads from each clip record."""
REPORT_CLIP_KEYS: tuple[str, ...] = (
    "id", "trial", "split", "mirror_of", "seconds", "frames", "licence", "source", "rig", "motion_type",
    "captions", "caption_origin", "description",
)
"""Fields ``simdiff data report`` reads from each clip record."""

_OPTIONAL_TYPES: dict[str, type | tuple[type, ...]] = {"counts": dict, "skipped": list, "sources": list}
"""Top-level fields that may be absent but, when present, must have this JSON type."""


def _kind(value: object) -> str:
    """The JSON name of ``value``'s type."""
    if value is None:
        return "null"
    return {dict: "an object", list: "a list", str: "a string", bool: "a boolean", int: "a number",
            float: "a number"}.get(type(value), type(value).__name__)


def manifest_path(corpus: str | Path) -> Path:
    """``corpus/manifest.json``."""
    return Path(corpus) / MANIFEST_NAME


def read_manifest(corpus: str | Path, clip_keys: Sequence[str] = CLIP_KEYS) -> dict[str, Any]:
    """The checked manifest of ``corpus``: a JSON object whose ``clips`` is a list of objects, each with
    ``clip_keys`` (``id`` always: a non-empty file stem, no path separators) and a whole-number ``frames``
    and a numeric ``seconds`` when those are asked for.

    Raises:
        SimdiffError: one line naming ``manifest.json`` and what is wrong with it.
    """
    path = manifest_path(corpus)
    if not path.exists():
        raise SimdiffError(f"{path}: missing (not a corpus of `simdiff data build`)")
    if not path.is_file():
        raise SimdiffError(f"{path}: not a regular file")
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise SimdiffError(f"{path}: cannot read the manifest ({getattr(exc, 'strerror', None) or exc})") from None
    try:
        data = json.loads(text)
    except ValueError as exc:
        raise SimdiffError(f"{path}: not valid JSON ({exc})") from None
    if not isinstance(data, dict):
        raise SimdiffError(f"{path}: not a corpus manifest (holds {_kind(data)}, not an object with a clips list)")
    clips = data.get("clips")
    if not isinstance(clips, list):
        raise SimdiffError(f"{path}: not a corpus manifest (clips is {_kind(clips) if 'clips' in data else 'missing'},"
                           f" not a list of clip records)")
    for key, kind in _OPTIONAL_TYPES.items():
        if key in data and not isinstance(data[key], kind):
            raise SimdiffError(f"{path}: {key} is {_kind(data[key])}, not {_kind(kind())}")
    keys = ("id", *[k for k in clip_keys if k != "id"])
    for i, clip in enumerate(clips):
        _check_clip(path, i, clip, keys)
    for i, item in enumerate(data.get("skipped", [])):
        if not isinstance(item, dict) or not isinstance(item.get("id"), str) or not isinstance(item.get("error"), str):
            raise SimdiffError(f"{path}: skipped[{i}] is not an object with an id and an error")
    return data


def _check_clip(path: Path, i: int, clip: object, keys: Sequence[str]) -> None:
    """Refuse clip record ``i`` unless it is an object with ``keys`` of usable types."""
    if not isinstance(clip, dict):
        raise SimdiffError(f"{path}: clips[{i}] is {_kind(clip)}, not a clip record object")
    if "id" not in clip:
        raise SimdiffError(f"{path}: clips[{i}] lacks id")
    cid = clip["id"]
    if not isinstance(cid, str) or not cid or cid.startswith(".") or any(c in cid for c in "/\\\0"):
        raise SimdiffError(f"{path}: clips[{i}] has id {cid!r}, not a plain file name")
    missing = [k for k in keys if k not in clip]
    if missing:
        raise SimdiffError(f"{path}: clip {cid} lacks {', '.join(missing)}")
    if "frames" in keys and (isinstance(clip["frames"], bool) or not isinstance(clip["frames"], int)
                             or clip["frames"] < 0):
        raise SimdiffError(f"{path}: clip {cid} has frames {clip['frames']!r}, not a whole number")
    if "seconds" in keys and (isinstance(clip["seconds"], bool) or not isinstance(clip["seconds"], (int, float))
                              or not 0 <= clip["seconds"] < float("inf")):
        raise SimdiffError(f"{path}: clip {cid} has seconds {clip['seconds']!r}, not a duration")
    if "captions" in keys and not (isinstance(clip["captions"], list) and clip["captions"]):
        raise SimdiffError(f"{path}: clip {cid} has no captions list")
    for key in ("motion_type", "licence", "source", "split", "trial", "caption_origin"):
        if key in keys and not isinstance(clip[key], str):
            raise SimdiffError(f"{path}: clip {cid} has {key} {clip[key]!r}, not a string")
    if "mirror_of" in keys and clip["mirror_of"] is not None and not isinstance(clip["mirror_of"], str):
        raise SimdiffError(f"{path}: clip {cid} has mirror_of {clip['mirror_of']!r}, not a clip id or null")
