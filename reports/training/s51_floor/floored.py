"""Session 51: run a script (benchmarks/model_check.py, float_probe.py) with every generated motion put on the floor
after the foot cleanup (simdiff.motion.floor.place_on_floor) -- the candidate of rule 30, before any plumbing.

usage: python reports/training/s51_floor/floored.py SCRIPT [ARGS...]
The model check's fingerprint carries foot_cleanup "2+floor", so no stored part of the unfloored runs is reused."""
import runpy
import sys

import simdiff.eval.model_check.run as R
import simdiff.motion.foot_lock as FL
from simdiff.motion.floor import place_on_floor

_clean = FL.clean_feet


def clean_then_floor(features, lengths=None, strength=1.0):
    return place_on_floor(_clean(features, lengths, strength), lengths)


FL.clean_feet = clean_then_floor  # the generator imports it from the module at call time
R.CLEANUP_VERSION = "2+floor"
sys.argv = sys.argv[1:]
runpy.run_path(sys.argv[0], run_name="__main__")
