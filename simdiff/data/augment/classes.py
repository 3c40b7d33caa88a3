"""Content classes of the augmented pairs and the keep-rate table per condition bin × class.

The quality checks (:mod:`simdiff.data.augment.checklist`) bound keep rates per content class, so the
report counts them that way:

* ``acrobatics``: the corpus manifest (``<corpus>/manifest.json``, per clip ``motion_type``)
  says ``acrobatics`` (no keep-rate bound in the quality checks);
* ``flight``: otherwise, the source clip's longest flight lasts at least
  :data:`simdiff.motion.flight.MIN_FLIGHT_S` (0.2 s), the rule of the corpus report
  (:func:`simdiff.motion.flight.has_flight` on ``content["flight_s"]``, the longest flight of
  :func:`simdiff.data.augment.signal.measure` on the source);
* ``plain``: every other clip ("without acrobatics" and without flight);
* ``unknown``: the source could not be read (no ``content``).

Without a manifest no clip is ``acrobatics`` (the report says so).
A second view keeps only the clips whose Earth rollout tracked: a clip the tracker cannot
follow even at Earth fails under every φ, and that failure is not φ's doing.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any

from simdiff.data.augment.decide import is_earth
from simdiff.data.augment.filter import CRITERIA, FilterConfig, rejections
from simdiff.data.augment.signal import condition_bin
from simdiff.motion.flight import has_flight

CLASSES: tuple[str, ...] = ("plain", "flight", "acrobatics", "unknown")
ACROBATICS: str = "acrobatics"
"""The manifest ``motion_type`` of the acrobatics class."""
MANIFEST: str = "manifest.json"


def bin_key(label: str) -> tuple[int, float]:
    """Sort key of a condition-bin label: Earth, then gravity, w_x, w_y bins by their lower edge."""
    if label == "earth":
        return (0, 0.0)
    name, _, rest = label.partition("[")
    return ({"g": 1, "wx": 2, "wy": 3}.get(name, 4), float(rest.split(",")[0]))


def load_motion_types(corpus: Path) -> dict[str, str] | None:
    """``{clip id: motion_type}`` from ``<corpus>/manifest.json`` (None when the corpus has none).

    Raises:
        SimdiffError: the manifest exists but is not JSON with a ``clips`` list of ``id``/``motion_type``.
    """
    from simdiff.data.manifest import read_manifest

    if not (Path(corpus) / MANIFEST).exists():
        return None
    clips = read_manifest(corpus, ("id",))["clips"]
    return {str(c["id"]): str(c.get("motion_type", "")) for c in clips}


def content_class(clip: str, content: dict[str, float] | None, motion_types: dict[str, str] | None) -> str:
    """Class of a source clip: ``acrobatics``, ``flight``, ``plain`` or ``unknown`` (module docstring)."""
    if motion_types is not None and motion_types.get(clip) == ACROBATICS:
        return ACROBATICS
    if not content:
        return "unknown"
    return "flight" if has_flight(content.get("flight_s", 0.0)) else "plain"


def clip_classes(records: Iterable[dict[str, Any]], motion_types: dict[str, str] | None) -> dict[str, str]:
    """``{clip: class}`` over the records (a clip's ``content`` is the same in all its records)."""
    content: dict[str, dict[str, float] | None] = {}
    for r in records:
        if r.get("content") or r["clip"] not in content:
            content[r["clip"]] = r.get("content")
    return {c: content_class(c, v, motion_types) for c, v in content.items()}


def earth_tracked(records: Iterable[dict[str, Any]]) -> set[str]:
    """Clips whose Earth pair tracked to the end (no fall, no error)."""
    return {r["clip"] for r in records
            if is_earth(r) and isinstance(r.get("info"), dict) and r["info"].get("success")}


def new_cell() -> dict[str, Any]:
    """An empty tally: pairs, kept, errors and each criterion's rejections."""
    return {"pairs": 0, "kept": 0, "error": 0, **{f"rejected_{c}": 0 for c in CRITERIA}}


def count(cell: dict[str, Any], record: dict[str, Any], filt: FilterConfig) -> None:
    """Add one decided record to a tally (each criterion judged on its own; an error counts as error only)."""
    cell["pairs"] += 1
    cell["kept"] += bool(record["kept"])
    if record.get("reason") == "error" or not isinstance(record.get("info"), dict):
        cell["error"] += 1
        return
    for c, v in rejections(record["info"], filt).items():
        cell[f"rejected_{c}"] += bool(v)


def close(cell: dict[str, Any]) -> dict[str, Any]:
    """The tally with its ``kept_fraction`` (None without pairs)."""
    cell["kept_fraction"] = cell["kept"] / cell["pairs"] if cell["pairs"] else None
    return cell


def class_table(records: Sequence[dict[str, Any]], classes: dict[str, str], filt: FilterConfig,
                clips: set[str] | None = None) -> dict[str, dict[str, dict[str, Any]]]:
    """Tallies per condition bin × content class.

    Args:
        records: decided records (``clip``, ``env``, ``kept``, ``reason``, ``info``).
        classes: ``{clip: class}`` (:func:`clip_classes`).
        filt: the thresholds the decision used (for the per-criterion rejections).
        clips: only these clips (e.g. :func:`earth_tracked`); None = all.
    Returns:
        ``{bin: {class: {pairs, kept, kept_fraction, error, rejected_<criterion>}}}``, bins sorted,
        only the classes that occur in a bin.
    """
    table: dict[str, dict[str, dict[str, Any]]] = {}
    for r in records:
        if clips is not None and r["clip"] not in clips:
            continue
        row = table.setdefault(condition_bin(r["env"]), {})
        count(row.setdefault(classes.get(r["clip"], "unknown"), new_cell()), r, filt)
    return {b: {k: close(table[b][k]) for k in CLASSES if k in table[b]} for b in sorted(table, key=bin_key)}


def class_view(records: Sequence[dict[str, Any]], classes: dict[str, str], filt: FilterConfig,
               clips: set[str] | None, label: str) -> dict[str, Any]:
    """One labelled view: clips per class and the :func:`class_table` over ``clips``."""
    chosen = set(classes) if clips is None else set(classes) & clips
    return {"label": label, "clips": {k: sum(1 for c in chosen if classes[c] == k) for k in CLASSES},
            "table": class_table(records, classes, filt, clips)}


def pct(cell: dict[str, Any] | None) -> str:
    """``kept/pairs (xx %)`` of a tally, ``—`` without pairs."""
    if not cell or not cell["pairs"]:
        return "—"
    return f"{cell['kept']}/{cell['pairs']} ({100 * cell['kept_fraction']:.0f} %)"


def class_markdown(view: dict[str, Any]) -> list[str]:
    """A view as two Markdown tables: keep rate per bin × class, and what each criterion rejected."""
    present = [k for k in CLASSES if view["clips"].get(k)]
    clips = ", ".join(f"{k} {view['clips'][k]}" for k in present) or "none"
    lines = [f"### {view['label']}", "", f"clips per class: {clips}", "",
             "| bin | " + " | ".join(present) + " |", "|---" * (len(present) + 1) + "|"]
    for b, row in view["table"].items():
        lines.append(f"| {b} | " + " | ".join(pct(row.get(k)) for k in present) + " |")
    lines += ["", "Rejected per criterion, each judged on its own (fell / pose faithfulness / residual / error):", "",
              "| bin | " + " | ".join(present) + " |", "|---" * (len(present) + 1) + "|"]
    for b, row in view["table"].items():
        cells = []
        for k in present:
            c = row.get(k)
            cells.append("—" if not c else " / ".join(str(c[f"rejected_{x}"]) for x in CRITERIA) + f" / {c['error']}")
        lines.append(f"| {b} | " + " | ".join(cells) + " |")
    return lines + [""]
