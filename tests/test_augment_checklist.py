"""The augment report per content class, the Earth-tracked view and the quality checks.

Synthetic shard records with known outcomes: every clip is simulated 10 times in every condition
bin and a known number of those copies is made unfaithful (pose d_L2 over the bound), so the keep
rate of each bin × class is known exactly. Every clip keeps the same share of its pairs in each
bin relative to the others, so φ is uncorrelated with content among kept pairs (|r| = 0).
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from simdiff.data.augment import AugmentConfig, FilterConfig
from simdiff.data.augment.checklist import DoneWhen, gravity_bins, wind_bins
from simdiff.data.augment.classes import content_class, load_motion_types
from simdiff.data.augment.decide import decide
from simdiff.data.augment.report import build_report, report_markdown
from simdiff.data.augment.signal import GRAVITY_EDGES, WIND_EDGES, condition_bin
from simdiff.errors import SimdiffError

EARTH = [-9.81, 0.0, 0.0]
FILTER = FilterConfig(max_pose_d_l2=5.0, max_residual_n=70.6)
COPIES = 10


def _mid(edges: tuple[float, ...]) -> list[float]:
    return [(a + b) / 2 for a, b in zip(edges, edges[1:])]


def _envs() -> dict[str, list[float]]:
    envs = {"earth": EARTH}
    envs.update({condition_bin([g, 0, 0]): [g, 0.0, 0.0] for g in _mid(GRAVITY_EDGES)})
    envs.update({condition_bin([-9.81, w, 0]): [-9.81, w, 0.0] for w in _mid(WIND_EDGES)})
    envs.update({condition_bin([-9.81, 0, w]): [-9.81, 0.0, w] for w in _mid(WIND_EDGES)})
    return envs


def _signal(flight_s: float) -> dict[str, float]:
    keys = ("apex_gain_m", "apex_m", "cadence", "drift_x", "drift_z", "duration_s", "flight_total_s", "flights",
            "speed", "step_length_m", "steps")
    return {**{k: 0.0 for k in keys}, "flight_s": flight_s, "duration_s": 4.0}


def _clip(clip: str, flight_s: float, speed: float, keep: dict[str, int], fell: bool = False) -> list[dict]:
    """COPIES records per bin; ``keep[kind]`` of them faithful (kind: earth, gravity, wind, or a bin label)."""
    out = []
    for b, env in _envs().items():
        kind = b if b in keep else ("earth" if b == "earth" else "gravity" if b.startswith("g") else "wind")
        for i in range(COPIES):
            low_g = b == gravity_bins()[-1]
            sig = _signal(flight_s * (4.0 if low_g else 1.0)) if not fell else None
            out.append({"clip": clip, "condition": 0 if b == "earth" else 1, "id": f"{clip}_{b}_{i}", "env": env,
                        "written": not fell, "reason": None, "signal": sig,
                        "content": {"flight_s": flight_s, "flight_total_s": flight_s, "speed": speed},
                        "info": {"success": not fell, "d_l2_pose": 1.0 if i < keep[kind] else 9.0,
                                 "residual": {"force_mean_n": 10.0}, "cpu_s": 0.1, "n_out": 80}})
    return out


def _report(records: list[dict], motion_types: dict[str, str] | None = None) -> dict:
    decided, summary = decide(records, FILTER)
    return build_report(decided, [], AugmentConfig(mode="paired", conditions=6, filter=FILTER), summary,
                        motion_types=motion_types)


def _passing_records() -> list[dict]:
    # plain 6/10 at every gravity bin, flight 3/10; wind: (8 + 8 + 4)/30 ≥ 60 %; Earth (8+8+4+8)/40 = 70 %
    return (_clip("p0", 0.0, 1.2, {"earth": 8, "gravity": 6, "wind": 8})
            + _clip("p1", 0.15, 0.3, {"earth": 8, "gravity": 6, "wind": 8})  # a 0.15 s flight is not flight
            + _clip("f0", 0.3, 0.8, {"earth": 4, "gravity": 3, "wind": 4})
            + _clip("a0", 0.5, 2.0, {"earth": 8, "gravity": 6, "wind": 8}))


def _items(report: dict, view: str = "all") -> dict[str, dict]:
    return {i["key"]: i["views"][view] for i in report["checklist"]["items"]}


def test_content_class_follows_the_corpus_flight_rule_and_the_manifest(tmp_path: Path) -> None:
    types = {"a": "acrobatics", "b": "jump"}
    assert content_class("a", {"flight_s": 0.0}, types) == "acrobatics"
    assert content_class("b", {"flight_s": 0.2}, types) == "flight"
    assert content_class("b", {"flight_s": 0.19}, types) == "plain"
    assert content_class("a", {"flight_s": 0.3}, None) == "flight"  # no manifest: no acrobatics class
    assert content_class("c", None, types) == "unknown"
    assert load_motion_types(tmp_path) is None
    (tmp_path / "manifest.json").write_text(json.dumps({"clips": [{"id": "x", "motion_type": "acrobatics"}]}))
    assert load_motion_types(tmp_path) == {"x": "acrobatics"}
    (tmp_path / "manifest.json").write_text("{not json")
    with pytest.raises(SimdiffError, match="manifest.json"):
        load_motion_types(tmp_path)


def test_checklist_passes_when_every_class_meets_its_bound() -> None:
    report = _report(_passing_records(), {"a0": "acrobatics"})
    table = report["by_class"]["all"]["table"]
    assert report["by_class"]["all"]["clips"] == {"plain": 2, "flight": 1, "acrobatics": 1, "unknown": 0}
    for b in gravity_bins():
        assert table[b]["plain"]["kept_fraction"] == pytest.approx(0.6)
        assert table[b]["flight"]["kept_fraction"] == pytest.approx(0.3)
        assert table[b]["flight"]["rejected_faithfulness"] == 7 and table[b]["flight"]["rejected_failed"] == 0
    items = _items(report)
    assert items["plain_gravity"]["status"] == "PASS" and items["plain_gravity"]["value"] == pytest.approx(0.6)
    assert items["flight_gravity"]["value"] == pytest.approx(0.3)
    assert items["wind"]["value"] == pytest.approx(20 / 30) and items["wind"]["status"] == "PASS"
    assert items["earth"]["value"] == pytest.approx(28 / 40) and items["earth"]["status"] == "PASS"
    assert items["confound"]["status"] == "PASS" and items["confound"]["value"] < 1e-6
    assert items["low_g_flight"]["status"] == "PASS" and items["low_g_flight"]["value"] == pytest.approx(4.0)
    assert report["checklist"]["passes"] is True
    md = report_markdown(report)
    assert "Overall (all pairs): **PASS**" in md and "PASS 60.0 %" in md and "clips per class: plain 2, flight 1" in md
    row = next(line for line in md.splitlines() if line.startswith("| confound"))
    assert row.count(" | ") == 2 and "\\|r\\|" in row  # three cells: pipes in |r| are escaped


def test_checklist_fails_with_the_measured_value_and_the_earth_tracked_view_separates_tracker_failures() -> None:
    low = gravity_bins()[0]  # g[-20,-15)
    records = [r for r in _passing_records() if r["clip"] != "p1"]
    records += _clip("p1", 0.0, 0.3, {"earth": 8, "gravity": 6, "wind": 8, low: 2})
    records += _clip("bad", 0.0, 0.5, {"earth": 0, "gravity": 0, "wind": 0}, fell=True)  # falls even at Earth
    report = _report(records, {"a0": "acrobatics"})
    items = _items(report)
    plain = items["plain_gravity"]
    # all pairs: (6 + 0 + 0)/30 at g[-20,-15), (6 + 6 + 0)/30 elsewhere
    assert plain["status"] == "FAIL" and plain["where"] == low and plain["value"] == pytest.approx(8 / 30)
    assert set(plain["failing_bins"]) == set(gravity_bins())
    assert report["checklist"]["passes"] is False
    tracked = _items(report, "earth_tracked")["plain_gravity"]  # without the clip that fell at Earth
    assert tracked["status"] == "FAIL" and tracked["failing_bins"] == [low] and tracked["value"] == pytest.approx(0.4)
    rej = report["by_class"]["all"]["table"][low]["plain"]
    assert rej["rejected_failed"] == COPIES and rej["rejected_faithfulness"] == 4 + 8 + COPIES
    md = report_markdown(report)
    assert "Overall (all pairs): **FAIL**" in md and f"FAIL 26.7 % at {low} (8/30)" in md
    assert "Clips whose Earth rollout tracked" in md


def test_a_bin_without_pairs_is_no_data_and_not_a_pass() -> None:
    missing = gravity_bins()[-1]
    records = [r for r in _passing_records() if condition_bin(r["env"]) != missing]
    items = _items(_report(records))
    assert items["plain_gravity"]["status"] == "NO DATA" and items["plain_gravity"]["empty_bins"] == [missing]
    assert items["low_g_flight"]["status"] == "NO DATA"


def test_bounds_of_the_quality_checks() -> None:
    cfg = DoneWhen()
    assert (cfg.plain_gravity_keep, cfg.flight_gravity_keep, cfg.wind_keep, cfg.earth_keep, cfg.confound_r) == (
        0.5, 0.25, 0.6, 0.66, 0.1)
    assert len(gravity_bins()) == len(GRAVITY_EDGES) - 1 and len(wind_bins()) == 2 * (len(WIND_EDGES) - 1)


def test_cli_refinalises_with_auto_without_simulating_and_reads_the_manifest(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    from simdiff.cli.main import main
    from simdiff.data.humanml3d import read_split
    from simdiff.eval.testing import write_tiny_corpus

    corpus = write_tiny_corpus(tmp_path / "c", n_train=2, n_test=1, frames=40)
    clips = read_split(corpus / "train.txt")
    (corpus / "manifest.json").write_text(json.dumps({"clips": [{"id": clips[0], "motion_type": "acrobatics"},
                                                                {"id": clips[1], "motion_type": "walk"}]}))
    out = tmp_path / "aug"
    args = ["data", "augment", "--corpus", str(corpus), "--out", str(out), "--conditions", "1", "--backend", "serial",
            "--no-progress"]
    assert main(args + ["--max-pose-d-l2", "1e9", "--max-residual-n", "1e9"]) == 0
    shards = {p.name: p.read_bytes() for p in (out / "shards").iterdir()}

    def no_simulation(*a: object, **k: object) -> None:
        raise AssertionError("re-finalising must not simulate")

    monkeypatch.setattr("simdiff.sim.pool._run_one", no_simulation)
    assert main(args + ["--max-pose-d-l2", "auto"]) == 0
    assert {p.name: p.read_bytes() for p in (out / "shards").iterdir()} == shards
    report = json.loads((out / "report.json").read_text())
    assert report["filter"]["calibration"]["earth_keep_target"] == 0.66
    assert report["by_class"]["all"]["clips"]["acrobatics"] == 1 and report["motion_types"] == "manifest"
    assert "## Quality checks" in (out / "report.md").read_text()
