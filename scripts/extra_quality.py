"""Retarget quality of every file of the extra mocap sources (and CMU AMC as the reference).

For each file: ``simdiff.motion.io.load_joints`` (20 fps, floor at 0), then the physics
metrics of ``simdiff.motion.metrics`` (penetration, floating, sliding, skate ratio) and body
measures: head-joint height (90th percentile over frames), leg length (hip-knee-ankle,
mean of both sides) and trunk length (hip centre -> neck). Results are cached one JSON line
per file (resumable); the summary is a markdown table of per-source medians.

Usage (the archives extracted with ``tar -xJf`` into EXTRA, outside the repo):

    python scripts/extra_quality.py --extra /work/scratch/c12a/extra \\
        --cmu ../shared/data/cmu --out /work/scratch/c12a/quality
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

import numpy as np

from simdiff.errors import SimdiffError
from simdiff.motion.io import load_joints
from simdiff.motion.metrics import per_sample_physics_metrics

SOURCES: dict[str, str] = {
    "bandai-1": "bandai-namco/dataset/Bandai-Namco-Research-Motiondataset-1/data/*.bvh",
    "bandai-2": "bandai-namco/dataset/Bandai-Namco-Research-Motiondataset-2/data/*.bvh",
    "cmu-mb": "cmu-bvh/motionbuilder/*.bvh",
    "cmu-daz": "cmu-bvh/daz/*.bvh",
    "aclstm-salsa": "cmu-bvh/aclstm/salsa/*.bvh",
    "aclstm-martial": "cmu-bvh/aclstm/martial/*.bvh",
    "aclstm-indian": "cmu-bvh/aclstm/indian/*.bvh",
    "hdm05": "hdm05/*/*/*.amc",
    "deepmimic-xbpeng": "deepmimic-xbpeng/data/motions/**/*.txt",
}
"""Source name -> glob under the extracted archives folder."""

DIP: float = 0.05
"""Metres below the clip's ground (5th percentile of the per-frame lowest joint) that
counts a frame as sinking through the floor (``dip_frames``)."""
PROPS: float = 0.5
"""A clip whose lowest joint is within 15 cm of its floor in fewer than this fraction of
frames is flagged ``props`` (climbing, uneven terrain: the corpus ``support`` rule)."""


def measure(path: Path, **kwargs: object) -> dict[str, object]:
    """Metrics and body measures of one file (an "error" entry when it cannot be read)."""
    try:
        joints = load_joints(path, **kwargs)  # type: ignore[arg-type]
    except SimdiffError as exc:
        return {"file": str(path), "error": str(exc)}
    if joints.shape[0] < 2:
        return {"file": str(path), "error": f"only {joints.shape[0]} frames at 20 fps"}
    metrics = {k: float(v[0]) for k, v in per_sample_physics_metrics(joints).items()}
    hip_c = 0.5 * (joints[:, 1] + joints[:, 2])
    leg = np.mean([
        np.linalg.norm(joints[:, a] - joints[:, b], axis=-1).mean()
        for a, b in ((1, 4), (4, 7), (2, 5), (5, 8))
    ]) * 2
    lowest = joints[..., 1].min(axis=-1)
    ground = float(np.percentile(lowest, 5))
    return {
        "file": str(path),
        "frames20": int(joints.shape[0]),
        **metrics,
        "floating_median_frame": float(np.median(np.maximum(lowest - 0.005, 0.0)) * 1000),
        "head_p90": float(np.percentile(joints[:, 15, 1], 90)),
        "leg": float(leg),
        "trunk": float(np.linalg.norm(joints[:, 12] - hip_c, axis=-1).mean()),
        "contact15": float(np.mean(lowest <= 0.15)),
        "dip_frames": int(np.sum(lowest < ground - DIP)),
        "foot_ankle": float(np.mean([np.linalg.norm(joints[:, a] - joints[:, b], axis=-1).mean()
                                     for a, b in ((7, 10), (8, 11))])),
    }


def run(files: dict[str, list[Path]], cache: Path, kwargs: dict[str, dict[str, object]]) -> list[dict]:
    """Measure every file not yet in ``cache`` (one JSON line each); return all rows."""
    done: dict[str, dict] = {}
    if cache.is_file():
        for line in cache.read_text().splitlines():
            if line.strip():
                row = json.loads(line)
                done[row["file"]] = row
    total = sum(len(v) for v in files.values())
    count, start = 0, time.time()
    with open(cache, "a") as handle:
        for source, paths in files.items():
            for path in paths:
                count += 1
                if str(path) in done:
                    continue
                row = measure(path, **kwargs.get(source, {}))
                row["source"] = source
                done[str(path)] = row
                handle.write(json.dumps(row) + "\n")
                handle.flush()
                if count % 100 == 0:
                    print(f"{count}/{total} files, {time.time() - start:.0f} s", file=sys.stderr)
    rows = []
    for source, paths in files.items():
        for path in paths:
            row = done[str(path)]
            row["source"] = source
            rows.append(row)
    return rows


def summary(rows: list[dict]) -> str:
    """Markdown table of per-source medians over files."""
    head = ("| source | files | unusable | hours@20fps | floating mm | sliding mm/frame | skate | "
            "head p90 m | leg m | trunk m | ankle-toe m | props | dips |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    out = [head]
    sources = list(dict.fromkeys(r["source"] for r in rows))
    for source in sources:
        ok = [r for r in rows if r["source"] == source and "error" not in r]
        bad = [r for r in rows if r["source"] == source and "error" in r]
        if not ok:
            out.append(f"| {source} | {len(bad)} | {len(bad)} | | | | | | | | | | |")
            continue

        def med(key: str) -> float:
            return float(np.median([r[key] for r in ok]))

        hours = sum(r["frames20"] for r in ok) / 20 / 3600
        out.append(
            f"| {source} | {len(ok) + len(bad)} | {len(bad)} | {hours:.2f} | {med('floating'):.1f} | "
            f"{med('sliding'):.2f} | {med('skate_ratio'):.3f} | {med('head_p90'):.2f} | "
            f"{med('leg'):.2f} | {med('trunk'):.2f} | {med('foot_ankle'):.3f} | "
            f"{sum(r['contact15'] < PROPS for r in ok)} | "
            f"{sum(r['contact15'] >= PROPS and r['dip_frames'] > 0 for r in ok)} |"
        )
    return "\n".join(out)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--extra", type=Path, required=True, help="extracted extra archives")
    parser.add_argument("--cmu", type=Path, default=None, help="shared cmu folder (AMC reference)")
    parser.add_argument("--out", type=Path, required=True, help="cache and summary folder")
    parser.add_argument("--only", nargs="*", default=None, help="source names to run")
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    files: dict[str, list[Path]] = {}
    if args.cmu is not None and (args.only is None or "cmu-amc" in args.only):
        files["cmu-amc"] = sorted(p for p in (args.cmu / "amc").glob("*.amc")
                                  if not p.name.startswith("35_"))
    for source, pattern in SOURCES.items():
        if args.only is None or source in args.only:
            files[source] = sorted(args.extra.glob(pattern))
    rows = run(files, args.out / "quality.jsonl", {})
    table = summary(rows)
    (args.out / "summary.md").write_text(table + "\n")
    print(table)
    flags = []
    for r in rows:
        if "error" in r:
            flags.append(f"UNUSABLE {r['source']}: {r['error']}")
        elif r["contact15"] < PROPS:
            flags.append(f"PROPS {r['source']} {Path(r['file']).name}: lowest joint within 15 cm "
                         f"of the floor in {r['contact15']:.0%} of frames (floating {r['floating']:.0f} mm)")
        elif r["dip_frames"] > 0:
            flags.append(f"DIPS {r['source']} {Path(r['file']).name}: {r['dip_frames']} frames sink "
                         f"> {DIP * 100:.0f} cm below the ground (floating {r['floating']:.0f} mm)")
    (args.out / "flags.txt").write_text("\n".join(flags) + "\n")
    print("\n".join(flags))
    return 0


if __name__ == "__main__":
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    sys.exit(main())
