"""Session 52: run a script (benchmarks/model_check.py) with MotionGenerator.generate's env_guidance_fallback set --
rule 35's candidate before any plumbing into sampling.json / the CLI / the model check.

usage: FALLBACK=3 python reports/training/s52_runs_lowg/fallback.py SCRIPT [ARGS...]
The model check's fingerprint carries foot_cleanup "3+fallbackS", so no stored part of other runs is reused."""
import functools
import os
import runpy
import sys

import simdiff.eval.model_check.run as R
from simdiff.model.generator import MotionGenerator

FALLBACK = float(os.environ.get("FALLBACK", "3"))
_generate = MotionGenerator.generate


@functools.wraps(_generate)
def generate_with_fallback(self, *args, **kwargs):
    kwargs.setdefault("env_guidance_fallback", FALLBACK)
    return _generate(self, *args, **kwargs)


MotionGenerator.generate = generate_with_fallback
R.CLEANUP_VERSION = f"{R.CLEANUP_VERSION}+fallback{FALLBACK:g}"
sys.argv = sys.argv[1:]
runpy.run_path(sys.argv[0], run_name="__main__")
