"""Building blocks of the corpus report (``simdiff data report``, :mod:`simdiff.data.corpus.report`).

Manifest loading, Markdown tables, grouping and hours, per-clip physics metrics and
canonical-frame checks of ``new_joints`` ((T-1, 22, 3) metres, Y-up, 20 fps), the summary
figure and the filmstrips.
"""

from __future__ import annotations

import csv
import io
from collections import defaultdict
from pathlib import Path
from typing import Any, Protocol

import numpy as np

from simdiff.data.manifest import REPORT_CLIP_KEYS, read_manifest
from simdiff.data.writer import write_text
from simdiff.errors import SimdiffError
from simdiff.fsio import atomic_path
from simdiff.motion.skeleton import FPS


class FilmstripRenderer(Protocol):
    """Draws clips' (T, 22, 3) joints as one filmstrip image at ``path``; returns the path."""

    def __call__(self, motions: list[np.ndarray], path: Path, *, captions: list[str], n_frames: int) -> Path: ...


def load_manifest(corpus: Path) -> dict[str, Any]:
    """The ``manifest.json`` written by ``simdiff data build``, checked for every field the report reads
    (:func:`simdiff.data.manifest.read_manifest`)."""
    return read_manifest(corpus, REPORT_CLIP_KEYS)


def table(header: list[str], rows: list[list[object]]) -> str:
    """A Markdown table; floats with 2 decimals."""
    def cell(v: object) -> str:
        if isinstance(v, float):
            return f"{v:.2f}"
        return str(v)

    lines = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    lines += ["| " + " | ".join(cell(v) for v in row) + " |" for row in rows]
    return "\n".join(lines)


def group_by(clips: list[dict[str, Any]], key: str) -> dict[str, list[dict[str, Any]]]:
    """Clip records grouped by the value of ``key``, sorted by it."""
    out: dict[str, list[dict[str, Any]]] = defaultdict(list)
    for clip in clips:
        out[str(clip[key])].append(clip)
    return dict(sorted(out.items()))


def hours(clips: list[dict[str, Any]]) -> float:
    """Total duration of clip records, in hours."""
    return sum(float(c["seconds"]) for c in clips) / 3600


def frame_checks(joints: np.ndarray) -> dict[str, float]:
    """Canonical-frame checks of one (T, 22, 3) clip.

    Returns:
        floor (min y, m), facing0 (frame-0 facing angle from +Z, degrees), upright (fraction
        of frames whose head is above the pelvis), root_xz0 (frame-0 pelvis distance from the
        origin, m).
    """
    from simdiff.motion.kinematics import facing_direction
    from simdiff.motion.skeleton import FACE_JOINTS

    forward = facing_direction(joints[:1].astype(np.float64), FACE_JOINTS)[0]
    return {
        "floor": float(joints[..., 1].min()),
        "facing0": float(np.degrees(np.arctan2(forward[0], forward[2]))),
        "upright": float(np.mean(joints[:, 15, 1] > joints[:, 0, 1])),
        "root_xz0": float(np.hypot(joints[0, 0, 0], joints[0, 0, 2])),
    }


def clip_metrics(corpus: Path, clips: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Physics metrics and frame checks of every clip, read from ``new_joints``."""
    from tqdm import tqdm

    from simdiff.motion.metrics import per_sample_physics_metrics

    rows = []
    for clip in tqdm(clips, desc="metrics", unit="clip", dynamic_ncols=True, leave=False):
        joints = np.load(corpus / "new_joints" / f"{clip['id']}.npy")
        physics = {k: float(v[0]) for k, v in per_sample_physics_metrics(joints).items()}
        rows.append({
            "id": clip["id"], "trial": clip["trial"], "rig": clip["rig"], "split": clip["split"],
            "motion_type": clip["motion_type"], "frames": clip["frames"], "support": clip.get("support", ""),
            "ground_contact": clip.get("ground_contact", ""), **physics, **frame_checks(joints),
        })
    return rows


def stats(values: list[float]) -> list[float]:
    """Mean, median and 95th percentile."""
    arr = np.asarray(values, dtype=np.float64)
    return [float(arr.mean()), float(np.median(arr)), float(np.percentile(arr, 95))]


def summary_figure(path: Path, clips: list[dict[str, Any]], metrics: list[dict[str, Any]]) -> None:
    """``summary.png``: hours per split, source and motion type, clip lengths, skate and floating."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(13, 7.5), dpi=100, facecolor="white")
    FigureCanvasAgg(fig)
    axes = fig.subplots(2, 3)
    originals = [c for c in clips if c["mirror_of"] is None]
    for ax, key, title in ((axes[0, 0], "split", "hours per split"), (axes[0, 1], "rig", "hours per source"),
                           (axes[0, 2], "motion_type", "hours per motion type")):
        groups = group_by(clips, key)
        ax.bar(list(groups), [hours(v) for v in groups.values()], color="#4477aa")
        ax.set_title(f"{title} (with mirrors)")
        ax.tick_params(axis="x", rotation=0 if key == "split" else 45, labelsize=8)
    ax = axes[1, 0]
    ax.hist([c["frames"] / FPS for c in originals], bins=30, color="#66aa55")
    ax.set_title("clip length (s, originals)")
    by_id = {m["id"]: m for m in metrics}
    for ax, key, title in ((axes[1, 1], "skate_ratio", "foot skate ratio per clip"),
                           (axes[1, 2], "floating", "floating per clip (mm)")):
        for rig, group in group_by(originals, "rig").items():
            ax.hist([by_id[c["id"]][key] for c in group], bins=30, alpha=0.6, label=rig)
        ax.set_title(title)
        ax.legend(fontsize=8)
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, facecolor="white")


def pick_clips(clips: list[dict[str, Any]], rng: np.random.Generator, n: int) -> list[dict[str, Any]]:
    """Up to ``n`` original clips, preferring distinct trials and motion types."""
    pool = [c for c in clips if c["mirror_of"] is None]
    order = rng.permutation(len(pool))
    chosen, types, trials = [], set(), set()
    for strict in (True, False):
        for i in order:
            c = pool[int(i)]
            if c in chosen or len(chosen) >= n:
                continue
            if strict and (c["motion_type"] in types or c["trial"] in trials):
                continue
            chosen.append(c)
            types.add(c["motion_type"])
            trials.add(c["trial"])
    return chosen


def shown_caption(clip: dict[str, Any]) -> str:
    """The caption shown in figures: generated text, or a placeholder for third-party KIT-ML text."""
    return "[KIT-ML human caption]" if clip["caption_origin"] == "kitml" else str(clip["captions"][0])


def filmstrips(corpus: Path, out: Path, clips: list[dict[str, Any]], seed: int,
               render_filmstrip: FilmstripRenderer) -> list[tuple[str, Path]]:
    """Filmstrips of a few clips per source and per motion type (and a clip with its mirror), drawn by
    ``render_filmstrip`` (the caller passes :func:`simdiff.viz.stick.render_filmstrip`: rendering sits above the
    data layer); returns (title, image path) pairs."""
    rng = np.random.default_rng(seed)
    images = []
    groups = {f"source: {rig}": pick_clips(group, rng, 3) for rig, group in group_by(clips, "rig").items()}
    by_type = [pick_clips(group, rng, 1)[0] for group in group_by(clips, "motion_type").values() if pick_clips(group, rng, 1)]
    groups["one clip per motion type"] = by_type
    mirror = next((c for c in clips if c["mirror_of"] is not None and c["mirror_of"] == by_type[0]["id"]), None)
    if mirror is not None:
        original = next(c for c in clips if c["id"] == mirror["mirror_of"])
        groups["a clip and its mirror"] = [original, mirror]
    for title, chosen in groups.items():
        if not chosen:
            continue
        name = "filmstrip_" + title.split(":")[-1].strip().replace(" ", "_") + ".png"
        motions = [np.load(corpus / "new_joints" / f"{c['id']}.npy") for c in chosen]
        captions = [f"{c['id']} ({c['rig']}, {c['motion_type']}): {shown_caption(c)}" for c in chosen]
        images.append((title, render_filmstrip(motions, out / name, captions=captions, n_frames=8)))
    return images




def open_report(corpus: str | Path, out: str | Path | None) -> tuple[Path, dict[str, Any], Path, list[dict[str, Any]]]:
    """(corpus, manifest, report folder (created; default ``corpus/report``), clip records) of a built corpus.

    Raises:
        SimdiffError: no or invalid ``manifest.json``, or a manifest without clips.
    """
    corpus = Path(corpus)
    manifest = load_manifest(corpus)
    clips: list[dict[str, Any]] = manifest["clips"]
    if not clips:
        raise SimdiffError(f"{corpus}/manifest.json lists no clips")
    folder = Path(out) if out is not None else corpus / "report"
    folder.mkdir(parents=True, exist_ok=True)
    return corpus, manifest, folder, clips


def write_report_files(out: Path, md: list[str], metrics: list[dict[str, Any]]) -> Path:
    """Write ``report.md`` (the Markdown lines) and ``clip_metrics.csv`` (floats with 4 decimals)
    into ``out``; returns the path of ``report.md``."""
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=list(metrics[0].keys()), lineterminator="\n")
    writer.writeheader()
    for row in metrics:
        writer.writerow({k: (f"{v:.4f}" if isinstance(v, float) else v) for k, v in row.items()})
    write_text(out / "clip_metrics.csv", buffer.getvalue())
    report = out / "report.md"
    write_text(report, "\n".join(md) + "\n")
    return report
