"""CMU trials of ``shared/cmu`` (AMC, Character-Creator BVH, DeepMimic retargets) and the
extra CMU BVH of ``shared/extra/cmu-bvh`` (Motionbuilder and Daz rigs, acLSTM dances).

Every copy of one CMU trial gets the trial key ``cmu:SS_TT``; the registry keeps the best
(:data:`RANKS`: AMC, then Character-Creator BVH, Motionbuilder BVH, Daz BVH, DeepMimic) and
keeps the others as cross-checks. Captions of CMU trials come per window (KIT-ML, else CMU's
description) in :mod:`.clips`: ``cmu/manifest.jsonl``'s KIT-ML sentence plus every other
KIT-ML sentence of the trial in ``kitml/annotations.json``; acLSTM takes (trial ids unknown) get folder captions.
"""

from __future__ import annotations

import json
from pathlib import Path

from simdiff.data.corpus import cmu_captions
from simdiff.data.corpus.cmu_sources import Trial, discover as discover_cmu, normalise_trial
from simdiff.data.corpus.cmu_sources import read_descriptions, read_rates
from simdiff.data.corpus.archive import source_dir
from simdiff.data.corpus.item import Item

RANKS: dict[str, int] = {"cmu-amc": 0, "cmu-bvh": 1, "cmu-mb": 2, "cmu-daz": 3, "cmu-deepmimic": 4}
"""Preference among copies of one CMU trial (lower wins)."""

_RIG_SOURCE = {"amc": "cmu-amc", "bvh": "cmu-bvh", "deepmimic": "cmu-deepmimic"}

ACLSTM: dict[str, tuple[str, tuple[str, ...], tuple[str, ...]]] = {
    "salsa": ("dance", ("dances salsa", "dances a salsa", "does salsa dance steps"),
              ("with a partner's moves", "with lively hip movements", "to a salsa rhythm")),
    "martial": ("sports", ("performs martial arts moves", "practises martial arts", "does a martial arts routine"),
                ("with quick strikes", "with kicks and punches", "in a fighting stance")),
    "indian": ("dance", ("performs an indian dance", "does an indian dance", "dances in an indian style"),
               ("with graceful arm movements", "with expressive hand gestures", "gracefully")),
}
"""acLSTM folder -> (motion type, verb phrases, manners)."""


def read_kitml(shared: Path) -> dict[str, list[dict[str, object]]]:
    """CMU trial -> KIT-ML captions ``{"text", "start", "end"}`` from ``shared/kitml/annotations.json``."""
    path = shared / "kitml" / "annotations.json"
    out: dict[str, list[dict[str, object]]] = {}
    if not path.is_file():
        return out
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except ValueError:
        return out
    for entry in data.values():
        parts = str(entry.get("path", "")).split("/")
        if len(parts) < 3 or parts[0] != "CMU" or not parts[-1].endswith("_poses"):
            continue
        trial = normalise_trial(parts[-1][: -len("_poses")])
        if trial is None:
            continue
        for ann in entry.get("annotations", []):
            text = " ".join(str(ann.get("text", "")).split())
            if text:
                out.setdefault(trial, []).append(
                    {"text": text, "start": float(ann.get("start", 0.0)), "end": float(ann.get("end", 0.0))})
    return out


def _cmu_item(trial: Trial, source: str, path: Path, asf: Path | None, fps: float | None) -> Item:
    return Item(
        id=trial.trial, trial=f"cmu:{trial.trial}", source=source, path=path, licence="CMU",
        motion_type=cmu_captions.motion_type(trial.description),
        caption_origin="kitml" if trial.kitml else "cmu-description",
        description=trial.description, rank=RANKS[source], asf=asf, fps=fps,
        meta={"cmu_trial": trial},
    )


def discover(shared: Path, cache: Path) -> list[Item]:
    """Items of every CMU copy under ``shared`` (one per file; duplicates share ``trial``)."""
    items: list[Item] = []
    src = shared / "cmu"
    trials: dict[str, Trial] = {}
    kitml = read_kitml(shared)
    if src.is_dir() and any((src / d).exists() for d in ("amc", "bvh", "bvh.tar.xz", "deepmimic")):
        for trial in discover_cmu(src, cache / "cmu"):
            trials[trial.trial] = trial
            known = {" ".join(str(k["text"]).split()) for k in trial.kitml}
            trial.kitml = list(trial.kitml) + [k for k in kitml.get(trial.trial, []) if k["text"] not in known]
            for rig, path in sorted(trial.files.items()):
                if rig == "amc" and trial.asf is None:
                    continue
                items.append(_cmu_item(trial, _RIG_SOURCE[rig], path, trial.asf if rig == "amc" else None,
                                       trial.capture_fps if rig == "amc" else None))
    extra = source_dir(shared, cache, "cmu-bvh")
    if extra is None:
        return items
    rates, csv_desc = read_rates(src) if src.is_dir() else ({}, {})
    descriptions = {**csv_desc, **(read_descriptions(src) if src.is_dir() else {})}
    for folder, source in (("motionbuilder", "cmu-mb"), ("daz", "cmu-daz")):
        for path in sorted((extra / folder).glob("*.bvh")):
            name = normalise_trial(path.stem)
            if name is None:
                continue
            trial = trials.get(name) or Trial(trial=name, description=descriptions.get(name, ""),
                                              kitml=kitml.get(name, []), capture_fps=rates.get(name, 120.0))
            items.append(_cmu_item(trial, source, path, None, None))
    for folder, (kind, verbs, manners) in sorted(ACLSTM.items()):
        for path in sorted((extra / "aclstm" / folder).glob("*.bvh")):
            key = f"acl_{folder}_{path.stem}"
            items.append(Item(
                id=key, trial=f"aclstm:{folder}/{path.stem}", source="cmu-aclstm", path=path, licence="CMU",
                motion_type=kind, verbs=verbs, adverbs=manners,
                caption_origin="aclstm-folder", description=f"CMU {folder}", rank=0,
            ))
    return items
