"""Rule 95's selection S': for each candidate folder CAND (samples in CAND/<seed>/<prompt>/), the median speed of
each walk / run prompt over seeds 704-707 against the reference today's verdict holds it to, and the jumps of
CAND/704/a_person_jumps_forward; prints each candidate's margins and the chosen one ("X95 = ...").
Usage: python select95.py REPORT CAND...   (REPORT: a model-check report on corpus3 at 120 frames; exit 1: none)"""
from __future__ import annotations

import glob
import sys
from pathlib import Path

import numpy as np

from simdiff.eval.model_check.config import SPEED_PROMPTS
from simdiff.eval.model_check.detect import jump_stats, root_speed
from v94 import filled, speed_verdict

SEEDS = (704, 705, 706, 707)


def joints(pattern: str) -> list[np.ndarray]:
    out = [np.load(f) for f in sorted(glob.glob(pattern))]
    if not out:
        raise SystemExit(f"select95.py: no samples match {pattern}")
    return out


def judge(cand: str, types: dict) -> float | None:
    """The candidate's smallest margin (None when it fails)."""
    margins, ok = [], True
    for kind, prompts in SPEED_PROMPTS.items():
        medians = {p: float(np.median([root_speed(j) for s in SEEDS
                                       for j in joints(f"{cand}/{s}/{p.replace(' ', '_')}/sample*_joints.npy")]))
                   for p in prompts}
        v = speed_verdict(types, kind, medians)
        print(f"  {kind}: {'pass' if v['passed'] else 'FAIL'} ({v['detail']})")
        ok = ok and bool(v["passed"])
        margins += [min(m - lo, hi - m) / (hi - lo) for m, (lo, hi) in zip(v["value"], v["threshold"])]
    k = sum(bool(jump_stats(j)["jump"]) for j in joints(f"{cand}/704/a_person_jumps_forward/sample*_joints.npy"))
    print(f"  a person jumps forward: {k} of 8 jump (bar 6); smallest margin {min(margins):.3f}")
    return min(margins) if ok and k >= 6 else None


def main(report: str, *cands: str) -> bool:
    types = filled(Path(report))["speeds"]["types"]
    scores = {}
    for c in cands:
        print(c)
        scores[c] = judge(c, types)
    passed = {c: m for c, m in scores.items() if m is not None}
    print(f"X95 = {max(passed, key=passed.get)}" if passed else "S' FAIL: no candidate passes")
    return bool(passed)


if __name__ == "__main__":
    sys.exit(0 if main(*sys.argv[1:]) else 1)
