"""Session 52: run a script (benchmarks/model_check.py, float_probe.py) with every generated motion that never touches
the floor lowered onto it after the foot cleanup (simdiff.motion.floor.drop_floating) -- rule 32's candidate before
any plumbing.

usage: python reports/training/s52_runs_lowg/dropped.py SCRIPT [ARGS...]
The model check's fingerprint carries foot_cleanup "2+drop", so no stored part of the plain runs is reused."""
import runpy
import sys

import simdiff.eval.model_check.run as R
import simdiff.motion.foot_lock as FL
from simdiff.motion.floor import drop_floating

_clean = FL.clean_feet


def clean_then_drop(features, lengths=None, strength=1.0):
    return drop_floating(_clean(features, lengths, strength), lengths)


FL.clean_feet = clean_then_drop  # the generator imports it from the module at call time
R.CLEANUP_VERSION = "2+drop"
sys.argv = sys.argv[1:]
runpy.run_path(sys.argv[0], run_name="__main__")
