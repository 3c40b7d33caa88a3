"""Discover the CMU trials of a source folder and the files and metadata of each.

Source layout (``../shared/data/cmu``; every part but one motion folder is optional)::

    amc/SS_TT.amc + asf/SS.asf      CMU ASF/AMC, 120 fps (or CMU_data.csv's rate)
    bvh/SS_TT.bvh or bvh.tar.xz     Character-Creator BVH, 60 fps, frame 0 an added T-pose
    deepmimic/SS_TT.txt             DeepMimic humanoid3d JSON, 30 fps
    manifest.jsonl                  per trial: CMU description, KIT-ML captions, HumanML3D segments
    descriptions.tsv, CMU_data.csv  CMU descriptions and capture rates

HumanML3D split files (``train.txt``...) map segment ids to a split; the default place is
``<src>/../humanml3d/splits``.
"""

from __future__ import annotations

import csv
import json
import re
import tarfile
from dataclasses import dataclass, field
from pathlib import Path

from simdiff.errors import SimdiffError

RIGS: tuple[str, ...] = ("amc", "bvh", "deepmimic")
"""Source kinds in order of preference (fidelity): the first one present is primary."""

_TRIAL = re.compile(r"^(\d+)_(\d+)$")


@dataclass(frozen=True)
class Segment:
    """A HumanML3D segment of a trial: frames [start20, end20) at 20 fps, and its split."""

    hml_id: str
    start20: int
    end20: int
    split: str | None = None


@dataclass
class Trial:
    """One CMU trial and everything known about it.

    Attributes:
        trial: "SS_TT" (subject and trial numbers, zero-padded to 2 digits).
        description: CMU's short description ("" when unknown).
        kitml: KIT-ML captions as dicts ``{"text", "start", "end"}`` (seconds).
        segments: HumanML3D segments.
        files: rig kind -> motion file (amc, bvh, deepmimic).
        asf: ASF skeleton of the AMC file, when present.
        capture_fps: CMU capture rate (AMC frame rate), default 120.
    """

    trial: str
    description: str = ""
    kitml: list[dict[str, object]] = field(default_factory=list)
    segments: list[Segment] = field(default_factory=list)
    files: dict[str, Path] = field(default_factory=dict)
    asf: Path | None = None
    capture_fps: float = 120.0

    @property
    def subject(self) -> str:
        """Subject number "SS"."""
        return self.trial.split("_")[0]

    def usable_rigs(self, allowed: tuple[str, ...] = RIGS) -> list[str]:
        """Rig kinds among ``allowed`` that can be read (an AMC needs its ASF), best first."""
        return [r for r in RIGS if r in allowed and r in self.files and (r != "amc" or self.asf is not None)]

    def primary(self, allowed: tuple[str, ...] = RIGS) -> str | None:
        """The rig kind the corpus uses for this trial (None when nothing is usable)."""
        rigs = self.usable_rigs(allowed)
        return rigs[0] if rigs else None

    @property
    def hml3d_splits(self) -> set[str]:
        """HumanML3D splits its segments belong to."""
        return {s.split for s in self.segments if s.split}


def normalise_trial(name: str) -> str | None:
    """'2_1', '02_01' -> '02_01'; anything else -> None."""
    match = _TRIAL.match(name)
    if not match:
        return None
    return f"{int(match.group(1)):02d}_{int(match.group(2)):02d}"


def read_split_map(splits_dir: Path | None) -> dict[str, str]:
    """HumanML3D id -> split name from ``train/val/test.txt`` in ``splits_dir`` (may be absent)."""
    out: dict[str, str] = {}
    if splits_dir is None or not splits_dir.is_dir():
        return out
    for split in ("train", "val", "test"):
        path = splits_dir / f"{split}.txt"
        if path.is_file():
            for line in path.read_text().split():
                out.setdefault(line.strip(), split)
    return out


def read_descriptions(src: Path) -> dict[str, str]:
    out: dict[str, str] = {}
    path = src / "descriptions.tsv"
    if path.is_file():
        for line in path.read_text(encoding="utf-8", errors="replace").splitlines():
            parts = line.split("\t", 1)
            trial = normalise_trial(parts[0].strip())
            if trial and len(parts) == 2:
                out[trial] = parts[1].strip()
    return out


def read_rates(src: Path) -> tuple[dict[str, float], dict[str, str]]:
    rates: dict[str, float] = {}
    descriptions: dict[str, str] = {}
    path = src / "CMU_data.csv"
    if not path.is_file():
        return rates, descriptions
    with path.open(newline="", encoding="utf-8", errors="replace") as handle:
        for row in csv.DictReader(handle):
            try:
                trial = f"{int(row['Subject']):02d}_{int(row['Trial #']):02d}"
                rates[trial] = float(row["framerate"])
            except (KeyError, ValueError, TypeError):
                continue
            descriptions[trial] = (row.get("Motion Description") or "").strip()
    return rates, descriptions


def _read_manifest(src: Path, split_map: dict[str, str]) -> dict[str, dict[str, object]]:
    path = src / "manifest.jsonl"
    out: dict[str, dict[str, object]] = {}
    if not path.is_file():
        return out
    for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), start=1):
        if not line.strip():
            continue
        try:
            row = json.loads(line)
            trial = normalise_trial(str(row["trial"]))
        except (json.JSONDecodeError, KeyError, TypeError):
            raise SimdiffError(f"{path}:{number}: not a manifest row") from None
        if trial is None:
            raise SimdiffError(f"{path}:{number}: bad trial name {row.get('trial')!r}")
        segments = [
            Segment(str(s["hml_id"]), int(s["start20"]), int(s["end20"]), split_map.get(str(s["hml_id"])))
            for s in row.get("hml3d_segments", [])
        ]
        out[trial] = {
            "description": str(row.get("cmu_desc", "")),
            "kitml": [
                {"text": str(k["text"]), "start": float(k.get("start", 0.0)), "end": float(k.get("end", 0.0))}
                for k in row.get("kitml", []) if str(k.get("text", "")).strip()
            ],
            "segments": segments,
        }
    return out


def _bvh_files(src: Path, cache: Path) -> dict[str, Path]:
    """Trial -> BVH path, extracting ``bvh.tar.xz`` into ``cache`` on first use."""
    out: dict[str, Path] = {}
    folder = src / "bvh"
    if folder.is_dir():
        for path in sorted(folder.glob("*.bvh")):
            trial = normalise_trial(path.stem)
            if trial:
                out[trial] = path
    archive = src / "bvh.tar.xz"
    if archive.is_file():
        target = cache / "bvh"
        stamp = target / ".extracted"
        stat = archive.stat()
        key = f"{stat.st_size}:{stat.st_mtime_ns}"
        if not stamp.is_file() or stamp.read_text() != key:
            target.mkdir(parents=True, exist_ok=True)
            try:
                with tarfile.open(archive, "r:xz") as tar:
                    for member in tar.getmembers():
                        name = Path(member.name).name
                        if member.isfile() and name.endswith(".bvh") and normalise_trial(name[:-4]):
                            data = tar.extractfile(member)
                            if data is not None:
                                tmp = target / f".{name}.tmp"
                                tmp.write_bytes(data.read())
                                tmp.replace(target / name)
            except (tarfile.TarError, OSError, EOFError) as exc:
                raise SimdiffError(f"cannot read {archive}: {exc}") from None
            stamp.write_text(key)
        for path in sorted(target.glob("*.bvh")):
            trial = normalise_trial(path.stem)
            if trial and trial not in out:
                out[trial] = path
    return out


def discover(src: str | Path, cache: Path, splits_dir: Path | None = None) -> list[Trial]:
    """All trials with at least one motion file under ``src``, sorted by (subject, trial).

    Args:
        src: the CMU source folder.
        cache: scratch folder (the BVH archive is extracted into ``cache/bvh``).
        splits_dir: HumanML3D split files; default ``src/../humanml3d/splits`` if present.
    """
    src = Path(src)
    if not src.is_dir():
        raise SimdiffError(f"source folder not found: {src}")
    if splits_dir is None:
        splits_dir = src.parent / "humanml3d" / "splits"
    split_map = read_split_map(splits_dir)
    rates, csv_descriptions = read_rates(src)
    descriptions = {**csv_descriptions, **read_descriptions(src)}
    manifest = _read_manifest(src, split_map)

    trials: dict[str, Trial] = {}

    def get(trial: str) -> Trial:
        if trial not in trials:
            trials[trial] = Trial(trial=trial, capture_fps=rates.get(trial, 120.0))
        return trials[trial]

    amc_dir, asf_dir = src / "amc", src / "asf"
    if amc_dir.is_dir():
        for path in sorted(amc_dir.glob("*.amc")):
            trial = normalise_trial(path.stem)
            if trial is None:
                continue
            record = get(trial)
            record.files["amc"] = path
            for name in (f"{path.stem.split('_')[0]}.asf", f"{int(path.stem.split('_')[0]):02d}.asf"):
                if (asf_dir / name).is_file():
                    record.asf = asf_dir / name
                    break
    for trial, path in _bvh_files(src, cache).items():
        get(trial).files["bvh"] = path
    dm_dir = src / "deepmimic"
    if dm_dir.is_dir():
        for path in sorted(dm_dir.glob("*.txt")):
            trial = normalise_trial(path.stem)
            if trial:
                get(trial).files["deepmimic"] = path
    if not trials:
        raise SimdiffError(f"no motion files (amc/, bvh/, bvh.tar.xz, deepmimic/) under {src}")
    for trial, record in trials.items():
        info = manifest.get(trial, {})
        record.description = str(info.get("description") or descriptions.get(trial, ""))
        record.kitml = list(info.get("kitml", []))  # type: ignore[arg-type]
        record.segments = list(info.get("segments", []))  # type: ignore[arg-type]
    return sorted(trials.values(), key=lambda t: tuple(int(x) for x in t.trial.split("_")))
