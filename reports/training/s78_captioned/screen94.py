"""Rule 94's screen S: per walk / run prompt, the median mean horizontal pelvis speed of the samples in DIR/<prompt>/
against the reference today's verdict holds it to (clips captioned with it, else the length-matched clips of its
type, read from REPORT, a model-check report on corpus3 at 120 frames); jumps of DIR/a_person_jumps_forward.
(captioned quartiles filled in from corpus3 when REPORT lacks them). Usage: python screen94.py DIR REPORT   (exit 0 when S passes)"""
from __future__ import annotations

import glob
import sys
from pathlib import Path

import numpy as np

from simdiff.eval.model_check.config import SPEED_PROMPTS
from simdiff.eval.model_check.detect import jump_stats, root_speed
from v94 import filled, speed_verdict


def joints(folder: str) -> list[np.ndarray]:
    out = [np.load(f) for f in sorted(glob.glob(f"{folder}/sample*_joints.npy"))]
    if not out:
        raise SystemExit(f"screen94.py: no sample*_joints.npy in {folder}")
    return out


def main(folder: str, report: str) -> bool:
    types = filled(Path(report))["speeds"]["types"]
    ok = True
    for kind, prompts in SPEED_PROMPTS.items():
        medians = {}
        for p in prompts:
            v = [root_speed(j) for j in joints(f"{folder}/{p.replace(' ', '_')}")]
            medians[p] = float(np.median(v))
            print(f"{p}: n {len(v)} Q1/median/Q3 {np.percentile(v, [25, 50, 75]).round(3).tolist()}")
        v = speed_verdict(types, kind, medians)
        print(f"{kind}: {'PASS' if v['passed'] else 'FAIL'} ({v['detail']})")
        ok = ok and bool(v["passed"])
    jumps = joints(f"{folder}/a_person_jumps_forward")
    k = sum(bool(jump_stats(j)["jump"]) for j in jumps)
    print(f"a person jumps forward: {k} of {len(jumps)} jump (bar 6)")
    ok = ok and k >= 6
    print("S PASS" if ok else "S FAIL")
    return ok


if __name__ == "__main__":
    sys.exit(0 if main(*sys.argv[1:]) else 1)
