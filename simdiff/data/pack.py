"""A corpus as a few compact arrays (``simdiff train pack``), and back to the HumanML3D layout.

The pack stores the original clips' joints; features and mirrors are rebuilt on unpack (clip codec:
:mod:`simdiff.data.pack_joints`). On the all-source corpus that is 10x smaller than float16 features
(36.9 MiB against 378.6 MiB). A pack folder holds::

    pack.json              format, version 2, content "joints", counts, rel_step, the largest
                           rebuild error measured at pack time, sha256 of the index
    index.json.xz          clips [[id, joint offset, joint frames, contact offset]],
                           mirrors [[id, parent id, root scale, contact offset]],
                           raw [[id, row offset, rows]],
                           texts {id: caption file}, splits {name: [ids]},
                           files {name: text} (env.json, conditions.json, manifest.json, source_corpus.json)
    arrays/joints.npz      root (N, 3) float32 m; rel (N, 21, 3) int16 delta codes; contacts (bits);
                           raw (R, 263) float32 features of the few clips that do not rebuild
    arrays/Mean.npy, arrays/Std.npy   (263,) float32, copied exactly

Unpacking writes the HumanML3D layout (features (T, 263), joints (T, 22, 3) from the
features, texts, splits, side files); a clip with T feature rows is stored as T+1 joint frames.
"""

from __future__ import annotations

import hashlib
import json
import lzma
import multiprocessing as mp
import os
import shutil
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any

import numpy as np

from simdiff.data import pack_joints as codec
from simdiff.errors import SimdiffError
from simdiff.fsio import ensure_dir, save_npy, write_bytes, write_json
from simdiff.motion.features import features_to_joints

PACK_FORMAT = "simdiff-pack"
VERSION = 2
PACK_NAME = "pack.json"
INDEX_NAME = "index.json.xz"
ARRAYS_NAME = "joints.npz"
SIDE_FILES = ("env.json", "conditions.json", "manifest.json", "source_corpus.json")
DEFAULT_BUDGET_MIB = 64.0

Task = tuple[str, str, str | None]
"""(corpus folder, clip id, id of its mirror or None)."""


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


def _load_features(corpus: Path, clip: str) -> np.ndarray:
    path = corpus / "new_joint_vecs" / f"{clip}.npy"
    if not path.is_file():
        raise SimdiffError(f"{path}: listed in a split file but missing")
    arr = np.load(path, allow_pickle=False)
    if arr.ndim != 2 or arr.shape[1] != 263 or arr.shape[0] < 1:
        raise SimdiffError(f"{path}: expected (T, 263) features, got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise SimdiffError(f"{path}: non-finite features")
    return arr.astype(np.float32)


def _encode(task: Task) -> dict[str, Any]:
    """Worker: one clip (and its mirror candidate) → codes, contacts, mirror scale, each checked
    by rebuilding its features; a clip that does not rebuild within tolerance keeps its features."""
    corpus, clip, mirror = Path(task[0]), task[1], task[2]
    std = np.load(corpus / "Std.npy").astype(np.float64)
    features = _load_features(corpus, clip)
    out: dict[str, Any] = {"clip": clip, "contacts": features[:, codec.CONTACTS] > 0.5}
    try:
        root, rel = codec.quantize(codec.canonical_joints(features), clip)
    except SimdiffError:
        root = rel = None
    joints = None if root is None else codec.dequantize(root, rel)
    error = float("inf") if joints is None else codec.checked(lambda: codec.rebuild_features(joints), features, std)
    if error <= codec.TOLERANCE:
        out.update(root=root, rel=rel, error=error)
    else:
        out.update(raw=features, error=error)
    if mirror is not None:
        mfeat = _load_features(corpus, mirror)
        m: dict[str, Any] = {"id": mirror, "contacts": mfeat[:, codec.CONTACTS] > 0.5, "scale": 1.0,
                             "error": float("inf")}
        if "raw" not in out:
            m["scale"], m["error"] = codec.mirror_scale(joints, mfeat, std)
        if not m["error"] <= codec.TOLERANCE:
            m["raw"] = mfeat
        out["mirror"] = m
    return out


def _pool_map(fn: Callable[[Any], Any], tasks: list[Any], workers: int) -> Iterator[Any]:
    """``map`` over processes (spawned, one thread each) or in this process when workers <= 1."""
    if workers <= 1 or len(tasks) <= 1:
        yield from map(fn, tasks)
        return
    from simdiff.sim.pool import worker_init

    with ProcessPoolExecutor(max_workers=workers, mp_context=mp.get_context("spawn"), initializer=worker_init,
                             initargs=(1, os.getpid())) as pool:
        yield from pool.map(fn, tasks, chunksize=max(1, min(16, len(tasks) // (4 * workers))))


def _progress(items: Iterable[Any], total: int, desc: str, show: bool) -> Iterable[Any]:
    if not show:
        return items
    from tqdm import tqdm

    return tqdm(items, total=total, desc=desc, unit="clip")


def pack(corpus: str | Path, out: str | Path, budget_mib: float = DEFAULT_BUDGET_MIB,
         splits: list[str] | None = None, workers: int = 1, progress: bool = False) -> dict[str, Any]:
    """Pack ``corpus`` (HumanML3D layout) into ``out``; returns ``{clips, frames, bytes}``.

    Args:
        splits: pack only the clips of these split files (and those files); default every split.
        budget_mib: refuse (one-line error, nothing written) when the pack would exceed it; 0 = no check.
        workers: processes encoding clips (0: every core).
    Raises:
        SimdiffError: missing files, a clip with the wrong shape, or the pack over budget.
    """
    corpus, out = Path(corpus), Path(out)
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
    return _pack_clips(corpus, out, ids, all_splits, budget_mib, workers=resolve_workers(workers), progress=progress)


def _pack_clips(corpus: Path, out: Path, ids: list[str], splits: dict[str, list[str]], budget_mib: float,
                       workers: int = 1, progress: bool = False) -> dict[str, Any]:
    """Write a pack of ``ids`` of ``corpus`` into ``out`` (see module doc).

    Every clip's features are rebuilt here and compared with the corpus's: a clip ``M<x>``
    with ``<x>`` in ``ids`` is stored as a root scale (mirror of ``<x>``), any other as joints,
    when within :data:`~simdiff.data.pack_joints.TOLERANCE`; otherwise its features are stored
    as they are ("raw", float32). Returns ``{clips, mirrors, raw, frames, bytes, content,
    max_rebuild_error}``.
    """
    id_set = set(ids)
    candidates = {c: f"M{c}" for c in ids if f"M{c}" in id_set}
    tasks = [(str(corpus), c, candidates.get(c)) for c in ids if not (c.startswith("M") and c[1:] in candidates)]
    encoded = list(_progress(_pool_map(_encode, tasks, workers), len(tasks), "pack", progress))
    retry = [e["mirror"]["id"] for e in encoded if "raw" in e.get("mirror", {})]  # not a mirror: its own clip
    encoded = [{k: v for k, v in e.items() if not (k == "mirror" and "raw" in v)} for e in encoded]
    encoded += list(_pool_map(_encode, [(str(corpus), m, None) for m in retry], workers))
    clips, mirrors, raw_index, roots, rels, contacts, raws = [], [], [], [], [], [], []
    offset = contact_offset = raw_offset = 0
    errors = {"originals": 0.0, "mirrors": 0.0}
    for e in encoded:
        for item, parent in [(e, None)] + ([(e["mirror"], e["clip"])] if "mirror" in e else []):
            cid = item.get("clip", item.get("id"))
            if "raw" in item:
                raw_index.append([cid, raw_offset, len(item["raw"])])
                raws.append(item["raw"])
                raw_offset += len(item["raw"])
                continue
            kind = "originals" if parent is None else "mirrors"
            errors[kind] = max(errors[kind], item["error"])
            if parent is None:
                clips.append([cid, offset, len(item["root"]), contact_offset])
                roots.append(item["root"])
                rels.append(item["rel"])
                offset += len(item["root"])
            else:
                mirrors.append([cid, parent, item["scale"], contact_offset])
            contacts.append(item["contacts"])
            contact_offset += len(item["contacts"])
    texts = {}
    for clip in ids:
        path = corpus / "texts" / f"{clip}.txt"
        if path.is_file():
            texts[clip] = path.read_text(encoding="utf-8")
    side = {name: (corpus / name).read_text(encoding="utf-8") for name in SIDE_FILES if (corpus / name).is_file()}
    index = {"clips": clips, "mirrors": mirrors, "raw": raw_index, "texts": texts, "splits": splits, "files": side}
    blob = lzma.compress(json.dumps(index, separators=(",", ":"), ensure_ascii=False).encode("utf-8"), preset=9)
    frames = sum(c[2] for c in clips)
    tmp = out.with_name(f".{out.name}.tmp{os.getpid()}")
    shutil.rmtree(tmp, ignore_errors=True)
    try:
        ensure_dir(tmp / "arrays")
        rel = np.concatenate(rels) if rels else np.zeros((0, 21, 3), np.int16)
        bits = np.packbits(np.concatenate(contacts).reshape(-1)) if contacts else np.zeros(0, np.uint8)
        with open(tmp / "arrays" / ARRAYS_NAME, "wb") as handle:
            np.savez_compressed(handle, root=np.concatenate(roots) if roots else np.zeros((0, 3), np.float32),
                                rel=codec.delta_encode(rel), contacts=bits,
                                raw=np.concatenate(raws) if raws else np.zeros((0, 263), np.float32))
        for name in ("Mean.npy", "Std.npy"):
            save_npy(tmp / "arrays" / name, np.load(corpus / name).astype(np.float32))
        write_bytes(tmp / INDEX_NAME, blob)
        write_json(tmp / PACK_NAME, {"format": PACK_FORMAT, "version": VERSION, "content": "joints",
                                       "rel_step": codec.REL_STEP, "clips": len(clips), "mirrors": len(mirrors),
                                       "raw": len(raw_index), "joint_frames": frames,
                                       "max_rebuild_error": errors, "tolerance": codec.TOLERANCE,
                                       "index_sha256": hashlib.sha256(blob).hexdigest()})
        size = finish_pack(tmp, out, budget_mib)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return {"clips": len(clips) + len(mirrors) + len(raw_index), "mirrors": len(mirrors), "raw": len(raw_index),
            "frames": frames, "bytes": size, "content": "joints", "dtype": "int16+float32",
            "max_rebuild_error": errors}


def read_index(path: Path) -> dict[str, Any]:
    """The decompressed index of pack ``path`` (checked against pack.json's sha256)."""
    try:
        header = json.loads((path / PACK_NAME).read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        raise SimdiffError(f"{path / PACK_NAME}: cannot read pack index ({type(exc).__name__})") from None
    if not isinstance(header, dict) or header.get("format") != PACK_FORMAT or header.get("version") != VERSION:
        raise SimdiffError(f"{path / PACK_NAME}: not a {PACK_FORMAT} v{VERSION} index")
    try:
        blob = (path / INDEX_NAME).read_bytes()
    except OSError as exc:
        raise SimdiffError(f"{path / INDEX_NAME}: cannot read pack index ({type(exc).__name__})") from None
    if hashlib.sha256(blob).hexdigest() != header.get("index_sha256"):
        raise SimdiffError(f"{path / INDEX_NAME}: does not match pack.json (damaged or mixed pack)")
    try:
        return json.loads(lzma.decompress(blob).decode("utf-8"))
    except (lzma.LZMAError, ValueError) as exc:
        raise SimdiffError(f"{path / INDEX_NAME}: cannot decode ({type(exc).__name__})") from None


def _rebuild(task: tuple[str, str, np.ndarray, np.ndarray, list[tuple[str, float, np.ndarray]]]) -> list[str]:
    """Worker: write one clip's and its mirrors' features and joints into folder ``task[0]``."""
    folder, clip, joints, contacts, mirrors = task
    outputs = [(clip, codec.rebuild_features(joints), contacts)]
    outputs += [(mid, codec.rebuild_mirror(joints, scale), mc) for mid, scale, mc in mirrors]
    for cid, features, rows in outputs:
        features = np.asarray(features, dtype=np.float32)
        features[:, codec.CONTACTS] = rows
        np.save(Path(folder) / "new_joint_vecs" / f"{cid}.npy", features)
        np.save(Path(folder) / "new_joints" / f"{cid}.npy", np.asarray(features_to_joints(features), dtype=np.float32))
    return [o[0] for o in outputs]


def _finish_unpack(path: Path, index: dict[str, Any], tmp: Path, out: Path) -> None:
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
    """Write pack ``path`` as a HumanML3D-layout folder ``out`` (replaced as a whole); returns the clip count.
    ``workers``: processes rebuilding the features (0: every core)."""
    path, out = Path(path), Path(out)
    workers = resolve_workers(workers)
    index = read_index(path)
    arrays_path = path / "arrays" / ARRAYS_NAME
    try:
        with np.load(arrays_path, allow_pickle=False) as data:
            root, rel, bits = data["root"], codec.delta_decode(data["rel"]), data["contacts"]
            raw = data["raw"] if "raw" in data.files else np.zeros((0, 263), np.float32)
    except (OSError, KeyError, ValueError) as exc:
        raise SimdiffError(f"{arrays_path}: cannot read pack arrays ({type(exc).__name__})") from None
    last = max((o + n for _, o, n, _ in index["clips"]), default=0)
    if root.shape != (len(rel), 3) or rel.shape[1:] != (21, 3) or len(root) < last:
        raise SimdiffError(f"{arrays_path}: shapes {root.shape}, {rel.shape} do not match the index ({last} frames)")
    mirrors_of: dict[str, list[tuple[str, float, int]]] = {}
    for mid, parent, scale, coff in index["mirrors"]:
        mirrors_of.setdefault(parent, []).append((mid, float(scale), int(coff)))
    tmp = out.with_name(f".{out.name}.tmp{os.getpid()}")
    shutil.rmtree(tmp, ignore_errors=True)
    try:
        for sub in ("new_joint_vecs", "new_joints", "texts"):
            (tmp / sub).mkdir(parents=True)
        tasks = []
        for clip, offset, frames, coff in index["clips"]:
            rows = frames - 1
            joints = codec.dequantize(root[offset: offset + frames], rel[offset: offset + frames])
            tasks.append((str(tmp), clip, joints, codec.unpack_contacts(bits, coff, rows),
                          [(mid, s, codec.unpack_contacts(bits, mc, rows)) for mid, s, mc in mirrors_of.get(clip, [])]))
        done = sum(len(ids) for ids in _progress(_pool_map(_rebuild, tasks, workers), len(tasks), "unpack", progress))
        for clip, offset, rows in index.get("raw", []):
            features = np.asarray(raw[offset: offset + rows], dtype=np.float32)
            np.save(tmp / "new_joint_vecs" / f"{clip}.npy", features)
            np.save(tmp / "new_joints" / f"{clip}.npy", np.asarray(features_to_joints(features), dtype=np.float32))
            done += 1
        for clip, text in index["texts"].items():
            (tmp / "texts" / f"{clip}.txt").write_text(text, encoding="utf-8")
        _finish_unpack(path, index, tmp, out)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return done
