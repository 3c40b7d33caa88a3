"""Session 55 (rule 49, measuring before any plumbing): run a script (benchmarks/model_check.py, guard.py,
walk_probe.py) with the reference anchor used only at the late steps.

usage: ANCHOR_T0=500 python reports/training/s55_reference/late_anchor.py SCRIPT [ARGS...] (with --anchor reference)
With it, simdiff.diffusion.guidance.GuidedDenoiser computes the adapters anchor (the shipped guidance, bit for bit) at
every step whose timestep is above ANCHOR_T0 (of 1,000) and the reference anchor (rule 48) at the others. The report's
settings still say "anchor reference": the folder names carry the difference."""
import os
import runpy
import sys

import simdiff.diffusion.guidance as G

T0 = int(os.environ["ANCHOR_T0"])
_call = G.GuidedDenoiser.__call__


def _late(self, x, timesteps, cond):
    if self.anchor == "reference" and int(timesteps.max()) > T0:
        self.anchor = "adapters"
        try:
            return _call(self, x, timesteps, cond)
        finally:
            self.anchor = "reference"
    return _call(self, x, timesteps, cond)


G.GuidedDenoiser.__call__ = _late
sys.argv = sys.argv[1:]
sys.path.insert(0, os.path.dirname(os.path.abspath(sys.argv[0])))  # the script's own folder, as python SCRIPT has it
runpy.run_path(sys.argv[0], run_name="__main__")
