"""Prompt following: pass rates of kinematic checks per category, on real clips and on generated motions.

* **Ground truth**: the split's original clips whose captions match a rule of ``following.ground_truth`` are
  checked with the rule's detector (:mod:`simdiff.eval.detectors`): the detector's pass rate on real motion that
  was described that way. A category with no matching clip is one the corpus lacks (or never words that way).
* **Models**: every wording of the measured set (``following.wordings``; ``test`` = held-out wordings) × seeds, at
  Earth gravity without wind, decoded to the written joints as ``simdiff generate`` writes them; a motion passes
  when all its checks pass. ``speed:`` checks compare with the same seed of the wording's ``reference``.

Real clips' pass rates carry a 95 % Wilson interval; a model's, a 95 % percentile bootstrap over wordings (the seeds
of one wording are not independent draws of what users write).
"""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

import numpy as np

from simdiff.errors import SimdiffError
from simdiff.eval.detectors import parse_check, run_check, thresholds
from simdiff.eval.experiments.config import ModelSpec
from simdiff.eval.experiments.runner import EARTH, RowPlan, Runner, safe
from simdiff.eval.stats import wilson_interval

TITLE = "Prompt following — kinematic checks per category, real clips and generated motions"


def _prompts(runner: Runner) -> list[dict[str, Any]]:
    o = runner.config.following
    prompts = o.prompts.get(o.wordings)
    if not prompts:
        raise SimdiffError(f"following.prompts has no wordings set {o.wordings!r}; sets: {', '.join(o.prompts) or 'none'}")
    for p in prompts:
        if not isinstance(p, dict) or not p.get("text") or not p.get("category") or not p.get("checks"):
            raise SimdiffError(f"following prompt {p!r} needs 'category', 'text' and 'checks'")
        for check in p["checks"]:
            parse_check(check)
            if check.startswith("speed:") and not p.get("reference"):
                raise SimdiffError(f"following prompt {p['text']!r}: {check} needs a 'reference' wording")
    return prompts


def measure_ground_truth(runner: Runner) -> dict[str, Any]:
    """Per rule: the matching clips of the split, how many pass, and the readings of those that fail."""
    corpus = Path(runner.config.corpus).expanduser()
    manifest = json.loads((corpus / "manifest.json").read_text(encoding="utf-8"))
    clips = [c for c in manifest["clips"] if not c.get("mirror_of") and c.get("split") == runner.config.split]
    rules = []
    for rule in runner.config.following.ground_truth:
        if not isinstance(rule, dict) or not all(rule.get(k) for k in ("category", "check", "captions")):
            raise SimdiffError(f"ground-truth rule {rule!r} needs 'category', 'check' and 'captions'")
        parse_check(rule["check"])
        if rule["check"].startswith("speed:"):
            raise SimdiffError(f"ground-truth rule {rule['check']!r}: speed checks need a paired motion")
        pattern = re.compile(rule["captions"], re.IGNORECASE)
        exclude = re.compile(rule["exclude"], re.IGNORECASE) if rule.get("exclude") else None
        passed, failed = 0, []
        matched = [c for c in clips if any(pattern.search(t) and not (exclude and exclude.search(t))
                                           for t in c.get("captions", []))]
        for c in matched:
            path = corpus / "new_joints" / f"{c['id']}.npy"
            if not path.is_file():
                raise SimdiffError(f"{path}: missing (the corpus's manifest lists clip {c['id']!r})")
            verdict = run_check(np.load(path, allow_pickle=False), rule["check"])
            passed += verdict.passed
            if not verdict.passed:
                failed.append(f"{c['id']}: {verdict.reading}")
        rules.append({"category": rule["category"], "check": rule["check"], "n": len(matched), "passed": passed,
                      "failed": failed[:5]})
    return {"rules": rules}


def measure_model(runner: Runner, spec: ModelSpec) -> dict[str, Any]:
    """Every wording × seeds; per wording its category and the verdicts of every seed."""
    from simdiff.motion.rigid import batch_joints_from_features

    o = runner.config.following
    alpha = runner.alpha(spec) if runner.is_simdiff(spec) else None
    fn = runner.generate_fn(spec, "ddim", alpha, EARTH)

    def motions(text: str) -> np.ndarray:  # the same noise for every wording: seeds = batch positions
        feats, _ = runner.generate(fn, [text] * o.seeds, [o.length] * o.seeds, runner.config.seed)
        return batch_joints_from_features(feats, [o.length] * o.seeds, fn.foot_lock)

    out = []
    for p in _prompts(runner):
        joints = motions(p["text"])
        reference = motions(p["reference"]) if p.get("reference") else [None] * o.seeds
        seeds = []
        for j, ref in zip(joints, reference):
            verdicts = [run_check(j, check, ref) for check in p["checks"]]
            seeds.append({"passed": all(v.passed for v in verdicts), "readings": [v.reading for v in verdicts]})
        out.append({"category": p["category"], "text": p["text"], "checks": p["checks"], "seeds": seeds})
    return {"wordings": out}


def plan(runner: Runner) -> list[RowPlan]:
    c, o = runner.config, runner.config.following
    if o.seeds < 1 or not 40 <= o.length <= 196:
        raise SimdiffError(f"following needs seeds >= 1 and 40 <= length <= 196, got {o.seeds} and {o.length}")
    prompts = _prompts(runner)
    plans = [RowPlan("ground_truth", {"method": "ground truth", "category": "all"},
                     {"row": "following_gt", "rules": o.ground_truth, "detectors": thresholds(), **runner.data_inputs()}, 10.0,
                     measure_ground_truth)]
    n = sum(2 if p.get("reference") else 1 for p in prompts) * o.seeds
    for spec in c.models:  # one row per model: every category's wordings
        base = runner.method_inputs(spec, "ddim", runner.alpha(spec) if runner.is_simdiff(spec) else None, EARTH)
        inputs = {"row": "following", "prompts": prompts, "seeds": o.seeds, "length": o.length, "seed": c.seed,
                  "detectors": thresholds(), **base}
        plans.append(RowPlan(safe(spec.name), {"method": spec.name}, inputs, runner.motion_seconds(spec, "ddim", n),
                             lambda r, spec=spec: measure_model(r, spec)))
    return plans


def _rate(passed: int, n: int) -> str:
    """Real clips (independent): pass rate with its Wilson interval."""
    if not n:
        return "— (none)"
    lo, hi = wilson_interval(passed, n)
    return f"{passed / n:.0%} [{lo:.0%}–{hi:.0%}] ({passed}/{n})"


def _wording_rate(wordings: list[dict[str, Any]]) -> str:
    """Generated motions: pass rate with a bootstrap interval over wordings (a wording's seeds are not independent
    draws of what users write)."""
    from simdiff.eval.stats import bootstrap_interval

    seeds = [s["passed"] for w in wordings for s in w["seeds"]]
    if not seeds:
        return "— (none)"

    def share(units: list[Any]) -> float:
        runs = [s["passed"] for w in units for s in w["seeds"]]
        return float(np.mean(runs)) if runs else float("nan")

    _, lo, hi = bootstrap_interval(wordings, share)
    return f"{np.mean(seeds):.0%} [{lo:.0%}–{hi:.0%}] ({sum(seeds)}/{len(seeds)}, {len(wordings)} wordings)"


def finish(runner: Runner, report: dict[str, Any]) -> list[str]:
    o = runner.config.following
    rows = report["rows"]
    gt = next((r for r in rows if r["method"] == "ground truth"), {"rules": []})
    models = [r for r in rows if r["method"] != "ground truth"]
    categories = list(dict.fromkeys([r["category"] for r in gt["rules"]] +
                                    [w["category"] for r in models for w in r["wordings"]]))
    methods = list(dict.fromkeys(r["method"] for r in models))
    lines = [(f"Wordings: the `{o.wordings}` set of `configs/eval_following.json` ({o.seeds} seeds each, {o.length} "
             f"frames, Earth, no wind); real clips: the {runner.config.split} split's originals whose captions match "
             "a rule. A motion passes when every check of its wording passes. Pass rate [95 % interval: Wilson over "
             "real clips; bootstrap over wordings for models, coarse with 3–5 wordings: read the per-wording table] (passed/n). Detectors and thresholds: `simdiff/eval/detectors.py`."), "",
             "| category | real clips | " + " | ".join(methods) + " |", "|---|---|" + "---|" * len(methods)]
    for cat in categories:
        rules = [r for r in gt["rules"] if r["category"] == cat]
        real = _rate(sum(r["passed"] for r in rules), sum(r["n"] for r in rules))
        cells = [_wording_rate([w for r in models if r["method"] == m for w in r["wordings"] if w["category"] == cat])
                 for m in methods]
        lines.append(f"| {cat} | {real} | " + " | ".join(cells) + " |")
    lines += ["", "Real clips per detector (caption rule → check):", "", "| category | check | pass | failing (first) |",
              "|---|---|---|---|"]
    for r in gt["rules"]:
        lines.append(f"| {r['category']} | `{r['check']}` | {_rate(r['passed'], r['n'])} | "
                     f"{'; '.join(r['failed'][:2]) or '—'} |")
    for m in methods:
        lines += ["", f"{m}, per wording (readings of the first two seeds):", "",
                  "| category | wording | checks | passed | readings |", "|---|---|---|---|---|"]
        for r in (r for r in models if r["method"] == m):
            for w in r["wordings"]:
                k = sum(s["passed"] for s in w["seeds"])
                readings = " / ".join("; ".join(s["readings"]) for s in w["seeds"][:2])
                lines.append(f"| {w['category']} | {w['text']} | {', '.join(f'`{c}`' for c in w['checks'])} | "
                             f"{k}/{len(w['seeds'])} | {readings} |")
    return lines
