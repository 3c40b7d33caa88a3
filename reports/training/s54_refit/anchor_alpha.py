"""Session 54 (rule 46, descriptive): run a script (benchmarks/model_check.py, guard.py) with the backbone anchor's
text guidance at adapter strength ANCHOR_ALPHA instead of 0, before any plumbing.

usage: ANCHOR_ALPHA=0.25 python reports/training/s54_refit/anchor_alpha.py SCRIPT [ARGS...] --anchor backbone ...
With it, simdiff.diffusion.guidance's backbone anchor computes
    x0 = x0_a(empty) + s (x0_a(c) - x0_a(empty)) + s_e (x0(c, phi) - x0(c, phi_ref)),
where x0_a runs the adapters at ANCHOR_ALPHA (Earth's motion: the adapters at that strength) and the environment term
at the run's alpha. The report's settings still say "anchor backbone": the folder names carry the difference."""
import dataclasses
import os
import runpy
import sys

import simdiff.diffusion.guidance as G

ALPHA = float(os.environ["ANCHOR_ALPHA"])


def _replace(obj, **changes):
    if changes.get("alpha") == 0.0:  # only the anchor's text condition sets alpha to 0 in guidance.py
        changes["alpha"] = ALPHA
    return dataclasses.replace(obj, **changes)


G.replace = _replace
sys.argv = sys.argv[1:]
runpy.run_path(sys.argv[0], run_name="__main__")
