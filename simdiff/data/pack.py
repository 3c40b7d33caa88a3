"""A corpus as a few compact arrays (``simdiff train pack``), and back to the HumanML3D layout.

Two contents: ``joints`` (version 2, the default; :mod:`simdiff.data.pack_v2`: the original
clips' joints, features and mirrors rebuilt on unpack; 10x smaller than float16 features on the
all-source corpus) and ``features`` (version 1, below). :func:`unpack` reads both.

A version-1 pack folder holds::

    pack.json            format, dtype, clips [[id, offset, frames]], texts {id: caption file},
                         splits {name: [ids]}, files {name: text} (env.json, conditions.json)
    arrays/features.npy  (ΣT, 263) every clip's features, concatenated (float16 or float32)
    arrays/Mean.npy, arrays/Std.npy   (263,) float32, copied exactly

float32 packs round-trip bit-exactly; float16 packs within float16 rounding (relative error
≤ 2⁻¹¹ of each value; |x| < 6.1e-5 keeps an absolute error ≤ 6e-8). ``new_joints`` are not
stored: :func:`unpack` recomputes them from the features (``features_to_joints``), which is how
the corpus builders and the augmentation write them.
"""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path
from typing import Any

import numpy as np

from simdiff.errors import SimdiffError
from simdiff.fsio import ensure_dir, save_npy, write_json

PACK_FORMAT = "simdiff-pack"
PACK_VERSION = 1
PACK_NAME = "pack.json"
SIDE_FILES = ("env.json", "conditions.json")
DEFAULT_BUDGET_MIB = 64.0
CONTENTS = ("joints", "features")


def is_pack(path: str | Path) -> bool:
    """Whether ``path`` is a pack folder."""
    return (Path(path) / PACK_NAME).is_file()


def _split_files(corpus: Path) -> dict[str, list[str]]:
    splits = {}
    for path in sorted(corpus.glob("*.txt")):
        splits[path.stem] = [line.strip() for line in path.read_text(encoding="utf-8").splitlines() if line.strip()]
    return splits


def folder_size(folder: str | Path) -> int:
    """Bytes of all files under ``folder``."""
    return sum(p.stat().st_size for p in Path(folder).rglob("*") if p.is_file())


def finish_pack(tmp: Path, out: Path, budget_mib: float) -> int:
    """Check the finished pack folder ``tmp`` against ``budget_mib`` (0: no check), then let it replace
    ``out``; returns its size in bytes.

    Raises:
        SimdiffError: the pack is over budget (``out`` is left as it was).
    """
    size = folder_size(tmp)
    if budget_mib > 0 and size > budget_mib * 2**20:
        raise SimdiffError(f"{out}: pack is {size / 2**20:.1f} MiB, over the {budget_mib:g} MiB budget")
    if out.exists():
        shutil.rmtree(out)
    os.replace(tmp, out)
    return size


def resolve_workers(workers: int) -> int:
    """Processes for packing/unpacking: ``workers``, or every core when it is 0 or less."""
    return workers if workers > 0 else (os.cpu_count() or 1)


def pack(corpus: str | Path, out: str | Path, dtype: str = "float16", budget_mib: float = DEFAULT_BUDGET_MIB,
         splits: list[str] | None = None, content: str = "joints", workers: int = 1,
         progress: bool = False) -> dict[str, Any]:
    """Pack ``corpus`` (HumanML3D layout) into ``out``; returns ``{clips, frames, bytes}``.

    Args:
        splits: pack only the clips of these split files (and those files); default every split.
        budget_mib: refuse (one-line error, nothing written) when the pack would exceed it; 0 = no check.
        content: "joints" (version 2) or "features" (version 1, stored as ``dtype``).
        workers: processes encoding clips (joints content; 0: every core).
    Raises:
        SimdiffError: missing files, a clip with the wrong shape, or the pack over budget.
    """
    corpus, out = Path(corpus), Path(out)
    if content not in CONTENTS:
        raise SimdiffError(f"pack content must be one of {', '.join(CONTENTS)}, got {content!r}")
    if dtype not in ("float16", "float32"):
        raise SimdiffError(f"pack dtype must be float16 or float32, got {dtype!r}")
    for name in ("Mean.npy", "Std.npy"):
        if not (corpus / name).is_file():
            raise SimdiffError(f"{corpus / name}: missing (not a HumanML3D-layout corpus)")
    all_splits = _split_files(corpus)
    if splits is not None:
        unknown = [s for s in splits if s not in all_splits]
        if unknown:
            raise SimdiffError(f"{corpus}: no split file {unknown[0]}.txt")
        all_splits = {k: v for k, v in all_splits.items() if k in splits}
    ids = sorted({i for members in all_splits.values() for i in members})
    if not ids:
        raise SimdiffError(f"{corpus}: no clips listed in its split files")
    if content == "joints":
        from simdiff.data.pack_v2 import pack_joints_corpus

        return pack_joints_corpus(corpus, out, ids, all_splits, budget_mib, workers=resolve_workers(workers),
                                  progress=progress)
    shapes = {}
    for clip in ids:
        path = corpus / "new_joint_vecs" / f"{clip}.npy"
        if not path.is_file():
            raise SimdiffError(f"{path}: listed in a split file but missing")
        arr = np.load(path, mmap_mode="r")
        if arr.ndim != 2 or arr.shape[1] != 263:
            raise SimdiffError(f"{path}: expected (T, 263) features, got {arr.shape}")
        shapes[clip] = arr.shape[0]
    frames = sum(shapes.values())
    itemsize = np.dtype(dtype).itemsize
    estimate = frames * 263 * itemsize
    if budget_mib > 0 and estimate > budget_mib * 2**20:
        raise SimdiffError(f"{corpus}: {len(ids)} clips, {frames} frames need {estimate / 2**20:.1f} MiB as {dtype}, "
                           f"over the {budget_mib:g} MiB budget (pack fewer splits or use --budget-mib)")
    features = np.empty((frames, 263), dtype=dtype)
    clips, texts, offset = [], {}, 0
    for clip in ids:
        arr = np.load(corpus / "new_joint_vecs" / f"{clip}.npy").astype(np.float32)
        features[offset: offset + len(arr)] = arr
        clips.append([clip, offset, len(arr)])
        offset += len(arr)
        text_path = corpus / "texts" / f"{clip}.txt"
        if text_path.is_file():
            texts[clip] = text_path.read_text(encoding="utf-8")
    side = {name: (corpus / name).read_text(encoding="utf-8") for name in SIDE_FILES if (corpus / name).is_file()}
    tmp = out.with_name(f".{out.name}.tmp{os.getpid()}")
    shutil.rmtree(tmp, ignore_errors=True)
    try:
        save_npy(tmp / "arrays" / "features.npy", features)
        for name in ("Mean.npy", "Std.npy"):
            save_npy(tmp / "arrays" / name, np.load(corpus / name).astype(np.float32))
        write_json(tmp / PACK_NAME, {"format": PACK_FORMAT, "version": PACK_VERSION, "dtype": dtype, "clips": clips,
                                     "texts": texts, "splits": all_splits, "files": side}, indent=None)
        size = finish_pack(tmp, out, budget_mib)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return {"clips": len(ids), "frames": frames, "bytes": size, "dtype": dtype}


def pack_version(path: str | Path) -> int:
    """Format version of pack ``path`` (1: features, 2: joints)."""
    path = Path(path)
    try:
        index = json.loads((path / PACK_NAME).read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        raise SimdiffError(f"{path / PACK_NAME}: cannot read pack index ({type(exc).__name__})") from None
    if not isinstance(index, dict) or index.get("format") != PACK_FORMAT or index.get("version") not in (1, 2):
        raise SimdiffError(f"{path / PACK_NAME}: not a {PACK_FORMAT} v1 or v2 index")
    return int(index["version"])


def read_pack(path: str | Path) -> tuple[dict[str, Any], np.ndarray]:
    """``(index, features)`` of a version-1 pack (features memory-mapped)."""
    path = Path(path)
    try:
        index = json.loads((path / PACK_NAME).read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        raise SimdiffError(f"{path / PACK_NAME}: cannot read pack index ({type(exc).__name__})") from None
    if index.get("format") != PACK_FORMAT or index.get("version") != PACK_VERSION:
        raise SimdiffError(f"{path / PACK_NAME}: not a {PACK_FORMAT} v{PACK_VERSION} index")
    feats_path = path / "arrays" / "features.npy"
    if not feats_path.is_file():
        raise SimdiffError(f"{feats_path}: missing pack array")
    features = np.load(feats_path, mmap_mode="r")
    last = max((o + n for _, o, n in index["clips"]), default=0)
    if features.ndim != 2 or features.shape[1] != 263 or features.shape[0] < last:
        raise SimdiffError(f"{feats_path}: shape {features.shape} does not match the index ({last} frames)")
    return index, features


def finish_unpack(path: Path, index: dict[str, Any], tmp: Path, out: Path) -> None:
    """Write a pack's Mean/Std, split files and side files into ``tmp``, then let ``tmp`` replace ``out``."""
    for name in ("Mean.npy", "Std.npy"):
        shutil.copyfile(path / "arrays" / name, tmp / name)
    for name, members in index["splits"].items():
        (tmp / f"{name}.txt").write_text("".join(f"{m}\n" for m in members), encoding="utf-8")
    for name, text in index.get("files", {}).items():
        (tmp / name).write_text(text, encoding="utf-8")
    ensure_dir(out.parent)
    if out.exists():
        shutil.rmtree(out)
    os.replace(tmp, out)


def unpack(path: str | Path, out: str | Path, workers: int = 1, progress: bool = False) -> int:
    """Write pack ``path`` (version 1 or 2) as a HumanML3D-layout folder ``out`` (replaced as a
    whole); returns the clip count. ``workers``: processes rebuilding a version-2 pack's features (0: every core)."""
    from simdiff.motion.features import features_to_joints

    path, out = Path(path), Path(out)
    if pack_version(path) == 2:
        from simdiff.data.pack_v2 import unpack_joints

        return unpack_joints(path, out, workers=resolve_workers(workers), progress=progress)
    index, features = read_pack(path)
    tmp = out.with_name(f".{out.name}.tmp{os.getpid()}")
    shutil.rmtree(tmp, ignore_errors=True)
    try:
        for sub in ("new_joint_vecs", "new_joints", "texts"):
            (tmp / sub).mkdir(parents=True)
        for clip, offset, frames in index["clips"]:
            f = np.array(features[offset: offset + frames], dtype=np.float32)
            np.save(tmp / "new_joint_vecs" / f"{clip}.npy", f)
            np.save(tmp / "new_joints" / f"{clip}.npy", np.asarray(features_to_joints(f), dtype=np.float32))
            if clip in index["texts"]:
                (tmp / "texts" / f"{clip}.txt").write_text(index["texts"][clip], encoding="utf-8")
        finish_unpack(path, index, tmp, out)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return len(index["clips"])
