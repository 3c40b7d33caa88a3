"""Compare an unpacked corpus with the corpus it was packed from (issue 14, GPU budget).

    python scripts/pack_accuracy.py CORPUS UNPACKED [--json OUT.json]

Prints, for original clips and for mirrors (``M<id>`` whose ``<id>`` is in the corpus): the
max / mean absolute error of the features in normalised units (|a - b| / Std.npy), contacts
apart, the number of differing contact values, and the max / mean joint error (``new_joints``)
in mm; whether Mean/Std, splits and texts are identical.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np


def _ids(folder: Path) -> list[str]:
    ids: set[str] = set()
    for path in folder.glob("*.txt"):
        ids.update(line.strip() for line in path.read_text(encoding="utf-8").splitlines() if line.strip())
    return sorted(ids)


def compare(corpus: Path, back: Path) -> dict[str, object]:
    from simdiff.motion.features import features_to_joints

    std = np.load(corpus / "Std.npy").astype(np.float64)
    ids = _ids(corpus)
    id_set = set(ids)
    stats: dict[str, dict[str, float]] = {}
    for clip in ids:
        kind = "mirrors" if clip.startswith("M") and clip[1:] in id_set else "originals"
        s = stats.setdefault(kind, {"clips": 0, "feat_max": 0.0, "feat_sum": 0.0, "values": 0, "contacts_diff": 0,
                                    "joints_mm_max": 0.0, "joints_mm_sum": 0.0, "joint_values": 0})
        a = np.load(corpus / "new_joint_vecs" / f"{clip}.npy").astype(np.float64)
        b = np.load(back / "new_joint_vecs" / f"{clip}.npy").astype(np.float64)
        if a.shape != b.shape:
            raise SystemExit(f"{clip}: shape {a.shape} vs {b.shape}")
        err = np.abs(a - b) / std
        s["contacts_diff"] += int((err[:, 259:] > 0).sum())
        err = err[:, :259]
        s["clips"] += 1
        s["feat_max"] = max(s["feat_max"], float(err.max()))
        s["feat_sum"] += float(err.sum())
        s["values"] += err.size
        path = corpus / "new_joints" / f"{clip}.npy"
        ja = np.load(path) if path.is_file() else np.asarray(features_to_joints(a.astype(np.float32)))
        ja = ja.astype(np.float64)
        jb = np.load(back / "new_joints" / f"{clip}.npy").astype(np.float64)
        jerr = np.abs(ja - jb) * 1000.0
        s["joints_mm_max"] = max(s["joints_mm_max"], float(jerr.max()))
        s["joints_mm_sum"] += float(jerr.sum())
        s["joint_values"] += jerr.size
    out: dict[str, object] = {}
    for kind, s in stats.items():
        out[kind] = {"clips": s["clips"], "features_max_norm": s["feat_max"],
                     "features_mean_norm": s["feat_sum"] / max(s["values"], 1),
                     "contact_values_differing": s["contacts_diff"], "joints_max_mm": s["joints_mm_max"],
                     "joints_mean_mm": s["joints_mm_sum"] / max(s["joint_values"], 1)}
    out["mean_std_identical"] = all((corpus / n).read_bytes()[-263 * 4:] == (back / n).read_bytes()[-263 * 4:]
                                    and np.array_equal(np.load(corpus / n), np.load(back / n))
                                    for n in ("Mean.npy", "Std.npy"))
    out["splits_identical"] = all((back / p.name).read_text() == p.read_text() for p in corpus.glob("*.txt"))
    out["texts_identical"] = all((back / "texts" / f"{c}.txt").read_text(encoding="utf-8")
                                 == (corpus / "texts" / f"{c}.txt").read_text(encoding="utf-8") for c in ids)
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("corpus", type=Path)
    parser.add_argument("unpacked", type=Path)
    parser.add_argument("--json", type=Path)
    args = parser.parse_args(argv)
    result = compare(args.corpus, args.unpacked)
    text = json.dumps(result, indent=2)
    print(text)
    if args.json:
        args.json.write_text(text + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
