"""Report of a corpus built by ``simdiff data build`` (``simdiff data report``): markdown + PNG.

Sections: hours by source, licence, motion type and split (originals and with mirrors);
split stratification; captions per origin; flight time (:mod:`simdiff.motion.flight`); physics metrics
per source with the worst clips named; canonical-frame checks; dedupe cross-checks (kept
copy vs other copies of a trial); filmstrips per source; skipped items. Per-clip numbers
go to ``clip_metrics.csv``.
"""

from __future__ import annotations

from collections import Counter
from pathlib import Path
from typing import Any

import numpy as np

from simdiff.data.corpus.crosscheck import TARGET_M, crosscheck_items
from simdiff.data.corpus.report_blocks import (
    FilmstripRenderer,
    clip_metrics,
    filmstrips,
    group_by,
    hours,
    open_report,
    stats,
    summary_figure,
    table,
    write_report_files,
)
from simdiff.licences import LICENCES
from simdiff.motion.flight import (
    GROUND_PERCENTILE,
    LIFT,
    LIFT_EDGE,
    MIN_FLIGHT_S,
    MIN_FRAMES,
    flight_stats,
    has_flight,
)
from simdiff.runinfo import header_lines, run_info

SPLITS: tuple[str, ...] = ("train", "val", "test")
METRICS: tuple[str, ...] = ("penetration", "floating", "sliding", "skate_ratio")


def _hours_table(clips: list[dict[str, Any]], key: str) -> str:
    rows = []
    for name, group in group_by(clips, key).items():
        originals = [c for c in group if c["mirror_of"] is None]
        rows.append([name, len({c["trial"] for c in group}), len(originals), hours(originals), hours(group),
                     *[hours([c for c in originals if c["split"] == s]) for s in SPLITS]])
    return table([key, "trials", "clips (originals)", "hours (originals)", "hours (with mirrors)",
                   "h train", "h val", "h test"], rows)


def _stratification(originals: list[dict[str, Any]]) -> str:
    rows = []
    for kind, group in group_by(originals, "motion_type").items():
        trials = {s: {c["trial"] for c in group if c["split"] == s} for s in SPLITS}
        rows.append([kind, *[len(trials[s]) for s in SPLITS]])
    return table(["motion type", "train trials", "val trials", "test trials"], rows)


def _flight(joints: np.ndarray) -> dict[str, float]:
    """Total and longest flight (s) of one clip, the two columns of ``clip_metrics.csv``."""
    stats = flight_stats(joints)
    return {"flight_s": stats["flight_total_s"], "longest_flight_s": stats["flight_s"]}


def _flight_section(originals: list[dict[str, Any]], flights: dict[str, dict[str, float]]) -> list[str]:
    md = ["## Flight (both feet off the floor)", "",
          f"A flight is a run of at least {MIN_FRAMES} frames where every foot joint (both ankles and toes) is "
          f"more than {LIFT * 100:.0f} cm above its own ground level (its {GROUND_PERCENTILE:g}th percentile "
          f"height over the clip), extended to where all are still {LIFT_EDGE * 100:.0f} cm up; heights only "
          "(`simdiff.motion.flight`, the rule also used for augmented and generated motions). Original "
          "clips with `support: floor` only (a mirror flies as its original; `props` clips, hanging or "
          "climbing, are left out).", ""]
    originals = [c for c in originals if c.get("support", "floor") == "floor"]
    rows = []
    for source, group in [("all", originals)] + list(group_by(originals, "source").items()):
        f = [flights[c["id"]] for c in group]
        rows.append([source, len(group), sum(x["flight_s"] for x in f) / 60,
                     sum(1 for x in f if has_flight(x["longest_flight_s"])),
                     max((x["longest_flight_s"] for x in f), default=0.0)])
    md.append(table(["source", "clips", "flight time (min)", f"clips with a flight >= {MIN_FLIGHT_S} s",
                      "longest flight (s)"], rows))
    longest = sorted(originals, key=lambda c: (-flights[c["id"]]["longest_flight_s"], c["id"]))[:8]
    md += ["", "Longest flights (check: a wrong floor also reads as flight):", ""]
    md += [f"- `{c['id']}` ({c['source']}, {c['motion_type']}, {c['description']}): longest "
           f"{flights[c['id']]['longest_flight_s']:.2f} s, total {flights[c['id']]['flight_s']:.2f} s" for c in longest]
    return md


def _physics_section(originals: list[dict[str, Any]], by_id: dict[str, dict[str, Any]]) -> list[str]:
    md = ["## Physics metrics per source (ground truth, `new_joints`)", "",
          "Joint-based protocol of `simdiff.motion.metrics`: penetration / floating (mm per frame beyond 5 mm), "
          "sliding (mm per frame of the lowest joint on the ground), skate ratio. mean / median / p95 over "
          "original clips.", ""]
    rows = []
    for source, group in [("all", originals)] + list(group_by(originals, "source").items()):
        vals = [by_id[c["id"]] for c in group]
        rows.append([source, len(group)] + [" / ".join(f"{x:.2f}" for x in stats([v[k] for v in vals])) for k in METRICS])
    md.append(table(["source", "clips", "penetration mm", "floating mm", "sliding mm/frame", "skate ratio"], rows))
    md += ["", "Worst clips per metric:", ""]
    for key in METRICS:
        if max(by_id[c["id"]][key] for c in originals) <= 0:
            md.append(f"- {key}: 0 in every clip (the floor is the clip's lowest joint)")
            continue
        worst = sorted(originals, key=lambda c: (-by_id[c["id"]][key], c["id"]))[:4]
        md.append(f"- {key}: " + "; ".join(
            f"`{c['id']}` ({c['source']}, {c['description']}) {by_id[c['id']][key]:.2f}" for c in worst))
    md += ["", "Worst floating clip of each source:", ""]
    for source, group in group_by(originals, "source").items():
        c = max(group, key=lambda c: (by_id[c["id"]]["floating"], c["id"]))
        md.append(f"- {source}: `{c['id']}` ({c['description']}, support {c.get('support')}): floating "
                  f"{by_id[c['id']]['floating']:.1f} mm, skate {by_id[c['id']]['skate_ratio']:.2f}")
    return md


def _crosscheck_section(manifest: dict[str, Any], corpus: Path, progress: bool) -> list[str]:
    from simdiff.data.corpus.registry import discover_all

    md = ["## Dedupe cross-checks (kept copy vs other copies of one trial)", ""]
    shared = Path(str(manifest.get("shared", "")))
    if not shared.is_dir():
        return md + ["Skipped: the shared data folder of the build is not here."]
    items = [i for i in discover_all(shared, corpus / ".build", ["cmu"], manifest.get("licence", "all")) if i.alternates]
    rows = crosscheck_items(items, corpus / ".build" / "crosscheck_all.json", progress)
    ok = [r for r in rows if not r.get("error")]
    if not ok:
        return md + ["No trial arrives in more than one copy."]
    md += [f"{len(rows)} pairs; each copy retargeted by its own joint map at 120 fps and canonicalised like a "
           "corpus clip (canonical bone lengths, floor, facing +Z), then aligned in time (±0.2 s) and space (yaw "
           "+ translation); MPJPE = mean per-joint distance. Target ≤ "
           f"{TARGET_M * 100:.0f} cm.", ""]
    pair_rows = []
    for (kept, copy), group in sorted(Counter((r["kept"], r["copy"]) for r in ok).items()):
        del group
        vals = np.array([r["mpjpe"] for r in ok if (r["kept"], r["copy"]) == (kept, copy)])
        pose = np.array([r["pose_only"] for r in ok if (r["kept"], r["copy"]) == (kept, copy)])
        pair_rows.append([f"{kept} vs {copy}", len(vals), vals.mean() * 100, float(np.median(vals)) * 100,
                      pose.mean() * 100, f"{int(np.sum(vals <= TARGET_M))}/{len(vals)}"])
    md.append(table(["pair", "trials", "MPJPE mean cm", "MPJPE median cm", "pose-only mean cm", "<= target"], pair_rows))
    worst = sorted(ok, key=lambda r: -r["mpjpe"])[:6]
    md += ["", "Largest disagreements: " + "; ".join(
        f"`{r['trial']}` {r['kept']} vs {r['copy']} {r['mpjpe'] * 100:.1f} cm (worst joint {r['worst_joint']})"
        for r in worst)]
    failed = [r for r in rows if r.get("error")]
    if failed:
        md += ["", f"Copies that could not be compared ({len(failed)}): " + "; ".join(
            f"`{r['trial']}` {r['copy']}: {r['error'][-80:]}" for r in failed[:8])]
    return md


def write_corpus_report(corpus: str | Path, out: str | Path | None = None, *, render_filmstrip: FilmstripRenderer,
                        seed: int = 0, crosscheck: bool = True, progress: bool = True) -> Path:
    """Write ``report.md``, ``summary.png``, filmstrips (drawn by ``render_filmstrip``) and ``clip_metrics.csv``
    into ``out`` (default ``corpus/report``); returns the path of ``report.md``."""
    corpus, manifest, out, clips = open_report(corpus, out)
    originals = [c for c in clips if c["mirror_of"] is None]
    metrics = clip_metrics(corpus, originals)
    flights = {c["id"]: _flight(np.load(corpus / "new_joints" / f"{c['id']}.npy")) for c in originals}
    for row in metrics:
        row.update(flights[row["id"]])
    by_id = {m["id"]: m for m in metrics}
    counts = manifest.get("counts", {})
    md = ["# Text–motion corpus: report", "", *header_lines(run_info()), "",
          f"Built by `simdiff data build` (pipeline v{manifest.get('pipeline_version')}, licence set "
          f"`{manifest.get('licence')}`, seed {manifest.get('seed')}, sources {', '.join(manifest.get('sources', []))}). "
          "HumanML3D layout, 20 fps, 22 joints, 263-dim features; every clip has a mirrored `M…` copy.", "",
          "## Overview", ""]
    md.append(table(["clips", "originals", "trials", "hours (originals)", "hours (with mirrors)", "skipped items"], [[
        len(clips), len(originals), len({c["trial"] for c in clips}), hours(originals), hours(clips),
        counts.get("skipped_items", len(manifest.get("skipped", [])))]]))
    md += ["", "![summary](summary.png)", "", "## Hours by licence", ""]
    md.append(_hours_table(clips, "licence"))
    md += ["", "Licences: " + "; ".join(f"`{k}`: {v}" for k, v in LICENCES.items()) + ". `--licence permissive` "
           "keeps CMU and MIT only.", "", "## Hours by source", ""]
    md.append(_hours_table(clips, "source"))
    md += ["", "## Hours by motion type", ""]
    md.append(_hours_table(clips, "motion_type"))
    md += ["", "## Splits", "", "By trial (a trial's windows and mirrors share a split); CMU trials with "
           "HumanML3D segments follow HumanML3D; the rest are stratified by (source, motion type) so that every "
           "stratum of >= 3 trials has a test and a val trial.", ""]
    md.append(table(["split", "clips", "trials", "hours (originals)"], [
        [s, len([c for c in clips if c["split"] == s]), len({c["trial"] for c in clips if c["split"] == s}),
         hours([c for c in originals if c["split"] == s])] for s in SPLITS]))
    md += ["", _stratification(originals), "", "## Captions", ""]
    md.append(table(["origin", "clips", "captions per clip (min / mean)", "distinct sentences"], [
        [origin, len(g), f"{min(len(c['captions']) for c in g)} / {np.mean([len(c['captions']) for c in g]):.2f}",
         len({s for c in g for s in c["captions"]})] for origin, g in group_by(clips, "caption_origin").items()]))
    md += ["", "Examples of generated captions (KIT-ML human text is not reproduced here):", ""]
    for source, group in group_by(originals, "source").items():
        c = next((c for c in group if not c["caption_origin"].startswith("kitml")), None)
        if c is not None:
            md.append(f"- {source} `{c['id']}` ({c['description']}): " + " / ".join(f"“{s}”" for s in c["captions"]))
    md += [""] + _flight_section(originals, flights) + [""] + _physics_section(originals, by_id)
    floor = [m["floor"] for m in metrics]
    md += ["", "## Canonical frame checks (original clips)", ""]
    md.append(table(["check", "result"], [
        ["lowest joint over the clip (m)", f"min {min(floor):.4f}, max {max(floor):.4f}"],
        ["frame-0 facing angle from +Z (deg)", f"max {max(abs(m['facing0']) for m in metrics):.2f}"],
        ["frames with head above pelvis", f"mean {np.mean([m['upright'] for m in metrics]) * 100:.1f} %"],
    ]))
    md += [""] + (_crosscheck_section(manifest, corpus, progress) if crosscheck else ["## Dedupe cross-checks", "", "Skipped."])
    padded = [c for c in originals if c.get("padded_frames")]
    if padded:
        md += ["", f"Short takes (0.5-2 s) padded to 2 s by holding their first and last pose: {len(padded)} clips "
               f"({', '.join(f'{k} {v}' for k, v in sorted(Counter(c['source'] for c in padded).items()))})."]
    summary_figure(out / "summary.png", clips, metrics)
    md += ["", "## Filmstrips", "", "Each row: 8 evenly spaced frames of one clip as stored in `new_joints`.", ""]
    for title, image in filmstrips(corpus, out, clips, seed, render_filmstrip):
        md += [f"### {title}", "", f"![{title}]({image.name})", ""]
    skipped = manifest.get("skipped", [])
    if skipped:
        reasons: dict[str, list[str]] = {}
        for item in skipped:
            reason = "shorter than 0.5 s at 20 fps" if "shorter than" in item["error"] else item["error"].split(": ", 1)[-1][:100]
            reasons.setdefault(reason, []).append(item["id"])
        md += ["## Skipped items", ""]
        md += [f"- {r}: {len(ids)} ({', '.join(ids[:12])}{', …' if len(ids) > 12 else ''})" for r, ids in sorted(reasons.items())]
    return write_report_files(out, md, metrics)
