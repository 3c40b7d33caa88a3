"""What a model was trained on, and which licence its weights therefore fall under.

A model folder may hold ``provenance.json`` beside ``model.safetensors`` and ``config.json``::

    {"trained_on": [{"what": "backbone", "data": "corpus", "sources": ["cmu-amc", ...],
                     "hours": 0.43, "licences": {"CMU": 0.43}, "licence_set": "all", "note": ""}, ...],
     "weights_licence": "permissive (CMU)", "licence_terms": {"CMU": "..."}}

``hours`` counts original motion only (a mirrored ``M…`` clip adds nothing beyond its original),
over the clips the training actually read (the split of a corpus, the source clips behind the kept
pairs of an augmented folder). ``licences`` maps each licence code of
:data:`simdiff.licences.LICENCES` to its hours.

The rule (:func:`weights_licence`): the most restrictive licence among all the data used decides.
Any ``CC-BY-NC-4.0`` motion makes the weights non-commercial; else any ``CC-BY-SA-3.0`` motion makes
them share-alike; data of only ``CMU`` and ``MIT`` (or synthetic data) gives permissive weights; data
whose licence is not recorded makes the whole answer ``unknown``, since it could be anything.

An augmented folder (``simdiff data augment``) records its source corpus in
``source_corpus.json`` (``{"path": ..., "summary": {...}}``): :func:`provenance_from_corpus` follows
``path`` to that corpus's ``manifest.json`` when it still exists, else uses the recorded summary.
For a folder without this record, ``{"path": "<its corpus>"}`` written by hand is enough.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Iterable

from simdiff.errors import SimdiffError
from simdiff.fsio import read_json as _read_json

PROVENANCE_NAME = "provenance.json"
SOURCE_CORPUS_NAME = "source_corpus.json"
"""File of an augmented folder naming the corpus it was made from."""
UNKNOWN = "unknown"
WHAT: tuple[str, ...] = ("backbone", "adapters", "evaluator")
SYNTHETIC = "synthetic"

NON_COMMERCIAL = "CC-BY-NC-4.0"
SHARE_ALIKE = "CC-BY-SA-3.0"
PERMISSIVE_CODES: tuple[str, ...] = ("CMU", "MIT")
CMU_ONLY_FORMAT = "simdiff-cmu-corpus"
"""Manifest format of ``simdiff data build-cmu``: CMU trials only (AMC, BVH and DeepMimic copies), all CMU-licensed."""


def _known_codes() -> dict[str, str]:
    from simdiff.licences import LICENCES

    return LICENCES


@dataclass
class TrainingData:
    """One data folder a part of the network was trained on.

    Attributes:
        what: which part learnt from it: ``backbone``, ``adapters`` or ``evaluator``.
        data: the folder's name (``corpus``, ``aug_random``) or ``synthetic``.
        sources: motion sources of the clips used (``cmu-amc``, ``bandai``, ...).
        hours: hours of original (unmirrored) motion used; None when unknown.
        licences: licence code -> hours; empty when unknown (or synthetic).
        licence_set: the corpus's ``--licence`` set (``all`` / ``permissive``) when recorded.
        note: a plain sentence when something is unknown or was inferred.
    """

    what: str
    data: str
    sources: list[str] = field(default_factory=list)
    hours: float | None = None
    licences: dict[str, float] = field(default_factory=dict)
    licence_set: str | None = None
    note: str = ""

    @property
    def known(self) -> bool:
        """True when the licences of this data are recorded (synthetic data has none to record)."""
        return bool(self.licences) or self.data == SYNTHETIC

    def to_dict(self) -> dict[str, Any]:
        return dataclasses.asdict(self)


def weights_licence(trained_on: Iterable[TrainingData]) -> str:
    """The licence of weights trained on ``trained_on``: the most restrictive licence among the data wins.

    Returns one of ``"non-commercial (CC-BY-NC-4.0 motion in the training data)"``,
    ``"share-alike (CC-BY-SA-3.0 motion in the training data)"``, ``"permissive (CMU, MIT)"``
    (naming the codes present; ``"permissive (synthetic data only)"``), or ``"unknown (...)"``
    naming the data whose licence is not recorded.
    """
    parts = list(trained_on)
    if not parts:
        return f"{UNKNOWN} (no training data recorded)"
    unknown = [p.data for p in parts if not p.known]
    if unknown:
        return f"{UNKNOWN} (no licence record for {', '.join(sorted(set(unknown)))})"
    codes = {code for p in parts for code in p.licences}
    strange = sorted(codes - set(_known_codes()))
    if strange:
        return f"{UNKNOWN} (unrecognised licence code {', '.join(strange)})"
    if NON_COMMERCIAL in codes:
        return f"non-commercial ({NON_COMMERCIAL} motion in the training data)"
    if SHARE_ALIKE in codes:
        return f"share-alike ({SHARE_ALIKE} motion in the training data)"
    present = [c for c in PERMISSIVE_CODES if c in codes]
    return f"permissive ({', '.join(present)})" if present else "permissive (synthetic data only)"


@dataclass
class Provenance:
    """What a model was trained on (``trained_on``) and the licence that implies (``weights_licence``).

    ``weights_licence`` is derived from ``trained_on`` by :func:`weights_licence` when left empty. An entry equal
    to an earlier one is dropped (a warm start on the same data folder would otherwise list it once per run).
    """

    trained_on: list[TrainingData] = field(default_factory=list)
    weights_licence: str = ""

    def __post_init__(self) -> None:
        unique: list[TrainingData] = []
        for part in self.trained_on:
            if part not in unique:
                unique.append(part)
        self.trained_on = unique
        if not self.weights_licence:
            self.weights_licence = weights_licence(self.trained_on)

    def merged(self, other: Provenance) -> Provenance:
        """Both provenances' data (this one's first), with the licence re-derived over all of it."""
        return Provenance(self.trained_on + other.trained_on)

    def to_dict(self) -> dict[str, Any]:
        codes = sorted({c for p in self.trained_on for c in p.licences})
        terms = _known_codes()
        return {"trained_on": [p.to_dict() for p in self.trained_on], "weights_licence": self.weights_licence,
                "licence_terms": {c: terms.get(c, "unrecognised code") for c in codes}}

    @classmethod
    def from_dict(cls, data: Any, where: str = "provenance") -> Provenance:
        """Parse ``to_dict``'s output; a wrong shape is one :class:`SimdiffError` line naming ``where``."""
        if not isinstance(data, dict) or not isinstance(data.get("trained_on"), list):
            raise SimdiffError(f"{where}: expected an object with a 'trained_on' list")
        names = {f.name for f in dataclasses.fields(TrainingData)}
        parts = []
        for i, entry in enumerate(data["trained_on"]):
            if not isinstance(entry, dict) or not {"what", "data"} <= set(entry) or set(entry) - names:
                raise SimdiffError(f"{where}: trained_on[{i}] must have 'what' and 'data' and only {sorted(names)}")
            if entry["what"] not in WHAT:
                raise SimdiffError(f"{where}: trained_on[{i}].what is {entry['what']!r}, expected one of {', '.join(WHAT)}")
            licences = entry.get("licences", {})
            if not isinstance(licences, dict) or not all(isinstance(v, (int, float)) for v in licences.values()):
                raise SimdiffError(f"{where}: trained_on[{i}].licences must map licence codes to hours")
            hours = entry.get("hours")
            if hours is not None and not isinstance(hours, (int, float)):
                raise SimdiffError(f"{where}: trained_on[{i}].hours must be a number, got {hours!r}")
            parts.append(TrainingData(**{**entry, "licences": {str(k): float(v) for k, v in licences.items()},
                                         "sources": [str(s) for s in entry.get("sources", [])]}))
        licence = data.get("weights_licence", "")
        if not isinstance(licence, str):
            raise SimdiffError(f"{where}: weights_licence must be a string, got {licence!r}")
        return cls(parts, licence)


def unknown_data(what: str, folder: str | Path, why: str) -> TrainingData:
    """An entry for data whose licences are not recorded, saying ``why`` plainly."""
    return TrainingData(what=what, data=Path(folder).name or str(folder), note=f"licence unknown: {why}")


def synthetic_data(what: str, clips: int) -> TrainingData:
    """An entry for the trainer's ``--synthetic`` clips (random sinusoids: no third-party motion)."""
    return TrainingData(what=what, data=SYNTHETIC, hours=0.0,
                        note=f"{clips} synthetic clips (random sinusoids, no recorded motion)")


def _split_ids(folder: Path, split: str) -> set[str] | None:
    path = folder / f"{split}.txt"
    if not path.is_file():
        return None
    return {line.strip() for line in path.read_text(encoding="utf-8").splitlines() if line.strip()}


def summarize_manifest(manifest: Any, what: str, name: str, clip_ids: set[str] | None = None,
                       split: str | None = None, where: str = "manifest.json") -> TrainingData:
    """Summarise a corpus manifest's clips (those in ``clip_ids``, else those of ``split``, else all).

    Hours count each original once (a mirror counts as its original). A ``build-cmu`` manifest
    (:data:`CMU_ONLY_FORMAT`) has no per-clip licence: its clips are CMU trials, so CMU.
    """
    if not isinstance(manifest, dict) or not isinstance(manifest.get("clips"), list):
        return unknown_data(what, name, f"{where} has no clip list")
    clips = [c for c in manifest["clips"] if isinstance(c, dict) and "id" in c]
    if clip_ids is not None:
        clips = [c for c in clips if c["id"] in clip_ids]
    elif split is not None and any("split" in c for c in clips):
        clips = [c for c in clips if c.get("split") == split]
    cmu_only = manifest.get("format") == CMU_ONLY_FORMAT
    by_id = {c["id"]: c for c in manifest["clips"] if isinstance(c, dict) and "id" in c}
    originals: dict[str, dict[str, Any]] = {}
    for clip in clips:
        key = clip.get("mirror_of") or clip["id"]
        originals.setdefault(key, by_id.get(key, clip))
    licences: dict[str, float] = {}
    sources: set[str] = set()
    for clip in originals.values():
        code = "CMU" if cmu_only else clip.get("licence")
        if not isinstance(code, str):
            return unknown_data(what, name, f"clip {clip['id']} in {where} has no licence code")
        try:
            seconds = float(clip.get("seconds", 0.0))
        except (TypeError, ValueError):
            raise SimdiffError(f"{where}: clip {clip['id']} has seconds {clip.get('seconds')!r}, not a number") from None
        licences[code] = licences.get(code, 0.0) + seconds / 3600.0
        source = clip.get("source") if not cmu_only else f"cmu-{clip.get('rig', 'amc')}"
        if isinstance(source, str):
            sources.add(source)
    if not originals:
        return unknown_data(what, name, f"no clip of {where} matches the training data")
    hours = round(sum(licences.values()), 4)
    note = "build-cmu corpus: CMU trials only" if cmu_only else ""
    return TrainingData(what=what, data=name, sources=sorted(sources), hours=hours,
                        licences={k: round(v, 4) for k, v in sorted(licences.items())},
                        licence_set=None if cmu_only else manifest.get("licence"), note=note)


def augmented_sources(folder: Path) -> set[str]:
    """Source-corpus clip ids behind the kept pairs of augmented ``folder`` (its ``env.json``)."""
    env = _read_json(folder / "env.json")
    if not isinstance(env, dict):
        raise SimdiffError(f"{folder / 'env.json'}: expected an object of pair records")
    return {str(r["source"]) for r in env.values() if isinstance(r, dict) and "source" in r}


def source_record(corpus: str | Path, used: set[str]) -> dict[str, Any]:
    """What an augmented folder records about its source ``corpus`` (``source_corpus.json``)."""
    corpus = Path(corpus)
    manifest_path = corpus / "manifest.json"
    if manifest_path.is_file():
        summary = summarize_manifest(_read_json(manifest_path), "adapters", corpus.name, used, where=str(manifest_path))
    else:
        summary = unknown_data("adapters", corpus, f"{corpus} has no manifest.json")
    return {"path": str(corpus.resolve()), "summary": summary.to_dict()}


def provenance_from_corpus(corpus_dir: str | Path, what: str = "backbone", split: str = "train",
                           source: str | Path | None = None) -> Provenance:
    """Provenance of training on ``corpus_dir`` (the clips of its ``<split>.txt``, else those whose
    manifest ``split`` is ``split``), read from its ``manifest.json``.

    An augmented folder (``env.json``) is followed to its source corpus: the one its
    ``source_corpus.json`` names, else ``source`` (the corpus the caller says it came from), else
    the recorded summary; the clips counted are the sources of its kept pairs. A folder with
    neither a manifest nor a source gives licence ``unknown``.

    Raises:
        SimdiffError: a manifest or record that exists but cannot be read (one line, names the file).
    """
    folder = Path(corpus_dir)
    if what not in WHAT:
        raise SimdiffError(f"what must be one of {', '.join(WHAT)}, got {what!r}")
    name = folder.name or str(folder)
    if not folder.is_dir():
        raise SimdiffError(f"{folder}: not a data folder")
    if (folder / "manifest.json").is_file():
        manifest_path = folder / "manifest.json"  # the split file is what the trainer reads; else the clips' split
        return Provenance([summarize_manifest(_read_json(manifest_path), what, name, _split_ids(folder, split), split,
                                              where=str(manifest_path))])
    if not (folder / "env.json").is_file():
        return Provenance([unknown_data(what, folder, f"{folder} has no manifest.json")])
    used = augmented_sources(folder)
    record_path = folder / SOURCE_CORPUS_NAME
    record = _read_json(record_path) if record_path.is_file() else None
    if record is not None and not (isinstance(record, dict) and isinstance(record.get("path"), str)):
        raise SimdiffError(f"{record_path}: expected an object with the source corpus 'path'")
    candidates = ([Path(record["path"])] if record else []) + ([Path(source)] if source is not None else [])
    for corpus in candidates:
        if (corpus / "manifest.json").is_file():
            manifest_path = corpus / "manifest.json"
            part = summarize_manifest(_read_json(manifest_path), what, name, used, where=str(manifest_path))
            part.note = (part.note + "; " if part.note else "") + f"augmented from corpus {corpus.name}"
            return Provenance([part])
    if record is not None and isinstance(record.get("summary"), dict):
        recorded = Provenance.from_dict({"trained_on": [record["summary"]]}, str(record_path)).trained_on[0]
        recorded.what, recorded.data = what, name
        recorded.note = (recorded.note + "; " if recorded.note else "") + f"as recorded in {SOURCE_CORPUS_NAME}"
        return Provenance([recorded])
    return Provenance([unknown_data(what, folder, "augmented data that records no source corpus")])


def training_provenance(what: str, data: Iterable[str | Path] = (), split: str = "train",
                        init: str | Path | None = None, source: str | Path | None = None,
                        synthetic: int | None = None, adapters_init: str | Path | None = None,
                        data_note: str = "") -> Provenance:
    """Provenance of a ``simdiff train backbone|adapters`` run.

    Args:
        what: ``backbone`` or ``adapters``.
        data: the ``--data`` folders (each through :func:`provenance_from_corpus`).
        split: the split read from them.
        init: the backbone model folder (adapters: trained on frozen; backbone: a warm start); its
            ``provenance.json`` backbone entries come first (an ``unknown`` backbone entry when it has none;
            a SimDiff folder's adapter entries are left out: only its backbone is loaded).
        source: ``--source``: a corpus whose clips are also trained on (and the fallback
            source of augmented folders that record none).
        synthetic: ``--synthetic N``: N synthetic clips instead of ``data``.
        adapters_init: ``--adapters-init``: a SimDiff folder whose adapters the run starts from; its
            ``provenance.json`` adapter entries come last (an ``unknown`` one when it has none): the data
            they were trained on counts for the licence.
        data_note: a sentence added to the note of each ``data`` entry (e.g. the training targets used).
    """
    parts: list[TrainingData] = []
    if init is not None:
        base = read_provenance(init)
        parts += [p for p in base.trained_on if p.what == "backbone"] if base is not None else [
            unknown_data("backbone", init, f"the backbone folder {init} has no {PROVENANCE_NAME}")]
    if synthetic is not None:
        parts.append(synthetic_data(what, synthetic))
    for folder in data:
        entries = provenance_from_corpus(folder, what, split, source=source).trained_on
        if data_note:
            for entry in entries:
                entry.note = f"{entry.note}; {data_note}" if entry.note else data_note
        parts += entries
    if source is not None:
        parts += provenance_from_corpus(source, what, split).trained_on
    if adapters_init is not None:
        base = read_provenance(adapters_init)
        parts += [p for p in base.trained_on if p.what == "adapters"] if base is not None else [
            unknown_data("adapters", adapters_init, f"the warm start {adapters_init} has no {PROVENANCE_NAME}")]
    return Provenance(parts)


def write_provenance(model_dir: str | Path, prov: Provenance) -> Path:
    """Write ``model_dir/provenance.json`` atomically; returns its path."""
    from simdiff.fsio import write_json

    return write_json(Path(model_dir) / PROVENANCE_NAME, prov.to_dict())


def read_provenance(model_dir: str | Path) -> Provenance | None:
    """``model_dir/provenance.json`` (None when absent).

    Raises:
        SimdiffError: the file is not valid JSON or not a provenance record (one line, names it).
    """
    path = Path(model_dir) / PROVENANCE_NAME
    if not path.is_file():
        return None
    return Provenance.from_dict(_read_json(path), str(path))
